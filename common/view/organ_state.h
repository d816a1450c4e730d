/* SPDX-License-Identifier: Apache-2.0 */
/* organ_state: one organ's current mesh as a viewer rebuilds it from the
 * wire: the latest keyframe (MeshState) plus the newest delta (MeshDelta).
 *
 * Deltas are cumulative against their keyframe (see mesh_delta.h), so only
 * the newest one matters. It is kept (copied) whether or not its keyframe is
 * here: a delta applies only when organ, topology_version and keyframe_seq
 * match the keyframe, and a delta for a keyframe not yet seen waits until
 * that keyframe arrives (DDS orders samples per topic, not across topics, and
 * a late joiner may get the delta first).
 *
 * Topology changes (adaptive refinement, cutting): the server publishes a
 * keyframe with a higher topology_version (and keyframe_seq) and new vertex
 * and triangle counts; it replaces the drawn mesh whole. Keyframes are
 * ordered by (topology_version, keyframe_seq), and the server numbers both
 * upwards. A delta older than the drawn keyframe in that order is stale (its
 * vertex indices may mean other vertices now) and is ignored without
 * touching the delta kept for a newer keyframe; a keyframe replaces the mesh
 * whatever its numbers (MeshState arrives in order per organ, and a
 * restarted server starts again at 0), and drops a kept delta older than
 * itself. Everything is untrusted input: a rejected keyframe or delta leaves
 * the drawn mesh as it was. Not thread-safe; no DDS here, so it is testable
 * on plain arrays. */
#ifndef VISCERA_VIEWER_ORGAN_STATE_H
#define VISCERA_VIEWER_ORGAN_STATE_H

#include <stddef.h>
#include <stdint.h>

#include "verr.h"

/* Largest keyframe accepted (vertices, triangles): far above any organ the
 * server simulates at interactive rates, and it bounds what a bad sample can
 * make the viewer allocate. */
#define ORGAN_MAX_VERTS (1u << 22)
#define ORGAN_MAX_TRIS (1u << 23)

/* A delta as received; the arrays are borrowed. */
typedef struct organ_delta {
  uint32_t topology_version, keyframe_seq, frame_seq;
  uint64_t sim_time_ns;
  float quant_step;
  const uint32_t *indices;
  size_t count;
  const int16_t *dq;
  size_t dq_len;
} organ_delta_t;

typedef struct organ_state {
  int have_key;
  uint32_t topology_version, keyframe_seq;
  uint64_t sim_time_ns; /* of the keyframe, or of the applied delta */
  size_t nverts, ntris;
  float *key;                 /* 3 * nverts, the keyframe as published */
  float *cur;                 /* 3 * nverts, keyframe + applied delta: what is drawn */
  float *scratch;             /* 3 * nverts, a delta is applied here, then swapped in */
  uint32_t *tris;             /* 3 * ntris, every index < nverts */
  int applied;                /* cur includes a delta ... */
  uint32_t applied_frame_seq; /* ... with this frame_seq */
  /* The newest delta received (owned copy), applied or waiting. */
  int have_delta;
  organ_delta_t delta;
  uint32_t *delta_idx;
  int16_t *delta_dq;
  size_t delta_cap;
} organ_state_t;

/* Replaces the keyframe after validating it: positions a non-empty multiple
 * of 3 and finite, triangles a non-empty multiple of 3 with every index in
 * range, sizes within the limits above. Then applies the kept delta if it
 * belongs to this keyframe. Returns 0 when accepted; 1 when accepted but the
 * kept delta failed to apply (err says why; the delta is dropped); -1 when
 * the keyframe is rejected (err says why; the state is unchanged). */
int organ_state_set_keyframe(organ_state_t *o, uint32_t topology_version, uint32_t keyframe_seq, uint64_t sim_time_ns,
                             const float *pos, size_t npos, const uint32_t *tris, size_t ntri_idx, verr_t *err);

/* Keeps d as the newest delta and applies it when it belongs to the current
 * keyframe. Returns 1 when applied, 0 when kept for a keyframe not seen yet,
 * 2 when stale (older than the drawn keyframe: ignored, nothing changes),
 * -1 when rejected (malformed, or mesh_delta_apply refused it; err says why;
 * the drawn mesh is unchanged). */
int organ_state_delta(organ_state_t *o, const organ_delta_t *d, verr_t *err);

/* Applied delta's frame_seq, or -1 when cur is the bare keyframe. */
long long organ_state_frame_seq(const organ_state_t *o);

void organ_state_free(organ_state_t *o);

#endif
