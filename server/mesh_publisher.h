/* mesh_publisher: turns an organ's positions into MeshState keyframes and
 * cumulative MeshDelta frames (common/mesh_delta.h).
 *
 * A keyframe is published at start and whenever a displacement outgrows the
 * int16 delta range (keyframe_seq increments). Owns its buffers (allocated at
 * init, none per frame). Keeps byte counters for the delta-size benchmark. */
#ifndef VISCERA_MESH_PUBLISHER_H
#define VISCERA_MESH_PUBLISHER_H

#include <dds/dds.h>
#include <stddef.h>
#include <stdint.h>

#include "verr.h"

typedef struct mesh_publisher {
  uint32_t organ_id;
  uint32_t topology_version;
  uint32_t keyframe_seq;
  uint32_t frame_seq;
  float quant;
  size_t nverts, ntris;
  const uint32_t *tris; /* borrowed, lives as long as the organ */
  float *key;           /* 3 nverts: the last published keyframe */
  uint32_t *idx;
  int16_t *dq;
  dds_entity_t w_state, w_delta; /* 0: encode only (benchmarks) */
  /* Counters. */
  uint64_t frames, keyframes, delta_payload_bytes;
  long last_count; /* vertices in the last delta */
} mesh_publisher_t;

int mesh_publisher_init(mesh_publisher_t *mp, uint32_t organ_id, size_t nverts, const uint32_t *tris, size_t ntris,
                        float quant, dds_entity_t w_state, dds_entity_t w_delta, verr_t *err);
void mesh_publisher_destroy(mesh_publisher_t *mp);
/* Publishes x (3 nverts, double) as a new keyframe. */
int mesh_publisher_keyframe(mesh_publisher_t *mp, const double *x, uint64_t sim_time_ns);
/* Publishes a delta against the current keyframe, or a new keyframe when out
 * of range. Returns 1 if a keyframe was published, 0 for a delta, -1 on error. */
int mesh_publisher_frame(mesh_publisher_t *mp, const double *x, uint64_t sim_time_ns);
/* Wire payload of the last delta (indices + components + fixed fields), bytes. */
size_t mesh_publisher_last_delta_bytes(const mesh_publisher_t *mp);

#endif
