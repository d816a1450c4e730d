/* SPDX-License-Identifier: Apache-2.0 */
/* mesh_publisher: turns an organ's positions into MeshState keyframes and
 * cumulative MeshDelta frames (common/mesh_delta.h).
 *
 * A keyframe is published at start, whenever a displacement outgrows the
 * int16 delta range (keyframe_seq increments) and on a topology change
 * (mesh_publisher_retopo: topology_version increments, and keyframe_seq
 * too). Every keyframe and delta carries both, so a receiver applies a delta
 * only to the keyframe it was encoded against. One DDS instance per organ
 * (organ_id key) for its whole life: a topology change is a new sample of
 * the same instance, never a new instance. Owns its buffers (allocated at
 * init, grown on a topology change, none per frame). Keeps byte counters
 * for the benchmarks.
 *
 * Quiet frames (keepalive_ns > 0, scene key physics.publish_keepalive): a
 * frame whose delta equals the last one written (same keyframe, same
 * vertices, same quantised offsets: the organ has not moved by a
 * quantisation step) is not written, unless keepalive_ns of wall time
 * passed since the last write. Why: an organ at rest (asleep, or settled)
 * would send its viewers the same sample publish_hz times a second, each a
 * wake-up of every subscriber process. MeshDelta is transient-local
 * keep-last 1, so a late joiner still gets the last written delta, which
 * is the current shape. Wall time, not simulated time: a paused session's
 * viewers still see a sample every keepalive. A keyframe (range overflow,
 * retopo) always resets the comparison. frame_seq and `frames` count the
 * deltas written (a receiver sees no gap for a skipped frame), `skipped`
 * the others. keepalive_ns = 0 (the init value) writes every frame. */
#ifndef VISCERA_MESH_PUBLISHER_H
#define VISCERA_MESH_PUBLISHER_H

#include <dds/dds.h>
#include <stddef.h>
#include <stdint.h>

#include "verr.h"

typedef struct mesh_publisher {
  uint32_t organ_id;
  uint32_t topology_version; /* on the wire: 0 at init, +1 per retopo */
  uint32_t model_version;    /* the model's topology_version the surface came from (model.h) */
  uint32_t keyframe_seq;
  uint32_t frame_seq;
  float quant;
  size_t nverts, ntris;
  size_t cap_verts;     /* the buffers below hold this many vertices */
  const uint32_t *tris; /* borrowed from the model, until the next retopo */
  int broken;           /* a retopo failed (out of memory): nothing more is published */
  float *key;           /* 3 nverts: the last published keyframe */
  uint32_t *idx;
  int16_t *dq;
  dds_entity_t w_state, w_delta; /* 0: encode only (benchmarks) */
  /* Keyframe chunks (dds/key_chunks.h), set after init; 0: none. Every
   * keyframe is also written as its compact encoding in single-datagram
   * MeshKeyChunk samples, which survive a lossy link (issue 14); MeshState
   * stays the keyframe of record (recordings, re-simulation). */
  dds_entity_t w_chunk;
  uint32_t chunk_copies;   /* 1 or 2 (set with w_chunk; 0 = KEY_CHUNK_COPIES) */
  uint32_t chunks_written; /* chunks of the last set (their slots are live) */
  uint64_t chunk_sets, chunk_samples, chunk_payload_bytes, chunk_failures;
  uint64_t key_sim_time_ns; /* of the current keyframe */
  uint64_t chunk_rewrites;  /* sets written again for new readers (mesh_publisher_rechunk) */
  /* The current keyframe's chunk encoding (owned; NULL until first written,
   * dropped by the next keyframe): a new reader's copy is sent again
   * without deflating the same keyframe again in the step thread. */
  uint8_t *chunk_blob;
  size_t chunk_len;
  /* Counters. */
  uint64_t frames, keyframes, delta_payload_bytes, keyframe_payload_bytes, retopos;
  long last_count; /* vertices in the last delta */
  /* Quiet frames (above). */
  uint64_t keepalive_ns; /* 0: write every frame */
  uint64_t skipped;      /* frames not written: equal to the last written delta */
  int have_written;      /* written_idx/dq hold the last written delta of the current keyframe */
  long written_count;    /* vertices in it */
  uint64_t written_ns;   /* vtime_mono_ns() of its write */
  uint32_t *written_idx; /* cap_verts */
  int16_t *written_dq;   /* 3 cap_verts */
} mesh_publisher_t;

/* zlib level of the keyframe chunks: the fastest, since a keyframe is
 * encoded in the physics loop (the kidney: about 0.5 ms). */
#define MESH_PUBLISHER_CHUNK_LEVEL 1

int mesh_publisher_init(mesh_publisher_t *mp, uint32_t organ_id, size_t nverts, const uint32_t *tris, size_t ntris,
                        float quant, dds_entity_t w_state, dds_entity_t w_delta, verr_t *err);
void mesh_publisher_destroy(mesh_publisher_t *mp);
/* Publishes x (3 nverts, double) as a new keyframe. */
int mesh_publisher_keyframe(mesh_publisher_t *mp, const double *x, uint64_t sim_time_ns);
/* Publishes a delta against the current keyframe, or a new keyframe when out
 * of range. Returns 1 if a keyframe was published, 0 for a delta (written,
 * or skipped as a quiet frame: see above), -1 on error. */
int mesh_publisher_frame(mesh_publisher_t *mp, const double *x, uint64_t sim_time_ns);
/* Writes the current keyframe's chunks again, as new samples, for readers
 * that matched since it was written (the server calls it when the chunk
 * writer's matched count grew). Why: a transient-local late joiner gets the
 * history only after a heartbeat and its request, two round trips after it
 * found the writer; a new sample goes to every matched reader at once, one
 * way. Readers that hold the set ignore the repeat (same numbers and
 * digest). Returns 0, or -1 when nothing was written (no chunk writer, no
 * keyframe yet, or a failure: counted). */
int mesh_publisher_rechunk(mesh_publisher_t *mp);
/* Wire payload of the last delta (indices + components + fixed fields), bytes. */
size_t mesh_publisher_last_delta_bytes(const mesh_publisher_t *mp);
/* Wire payload of a keyframe of the current surface, bytes. */
size_t mesh_publisher_keyframe_bytes(const mesh_publisher_t *mp);

/* Adopts a new surface after a topology change: nverts vertices at x,
 * triangles tris (borrowed, like at init; indices < nverts), coming from
 * the model's topology version model_version. Grows the buffers if needed,
 * increments topology_version and publishes a keyframe of x at once; the
 * next delta is encoded against it. Returns 0, or -1 with err (bad
 * triangle index, or out of memory: then the publisher is broken and stops
 * publishing, since it no longer describes the model's surface; or the DDS
 * write failed). */
int mesh_publisher_retopo(mesh_publisher_t *mp, uint32_t model_version, size_t nverts, const uint32_t *tris,
                          size_t ntris, const double *x, uint64_t sim_time_ns, verr_t *err);

#endif
