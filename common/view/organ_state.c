/* SPDX-License-Identifier: Apache-2.0 */
#include "view/organ_state.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_delta.h"

/* (topology_version, keyframe_seq) of a delta against the drawn keyframe's:
 * <0 older, 0 the same, >0 newer. */
static int cmp_key(const organ_state_t *o, uint32_t topology_version, uint32_t keyframe_seq) {
  if (topology_version != o->topology_version) return topology_version < o->topology_version ? -1 : 1;
  if (keyframe_seq != o->keyframe_seq) return keyframe_seq < o->keyframe_seq ? -1 : 1;
  return 0;
}

static int delta_matches(const organ_state_t *o) {
  return o->have_key && o->have_delta && o->delta.topology_version == o->topology_version &&
         o->delta.keyframe_seq == o->keyframe_seq;
}

/* Applies the kept delta to the keyframe; on failure the kept delta is
 * dropped (it will never apply) and cur stays as it was. */
static int apply_kept_delta(organ_state_t *o, verr_t *err) {
  const organ_delta_t *d = &o->delta;
  if (mesh_delta_apply(o->key, o->nverts, d->quant_step, d->indices, d->count, d->dq, d->dq_len, o->scratch, err)) {
    o->have_delta = 0;
    return -1;
  }
  float *t = o->cur;
  o->cur = o->scratch;
  o->scratch = t;
  o->applied = 1;
  o->applied_frame_seq = d->frame_seq;
  o->sim_time_ns = d->sim_time_ns;
  return 0;
}

int organ_state_set_keyframe(organ_state_t *o, uint32_t topology_version, uint32_t keyframe_seq, uint64_t sim_time_ns,
                             const float *pos, size_t npos, const uint32_t *tris, size_t ntri_idx, verr_t *err) {
  if (npos == 0 || npos % 3) return verr_set(err, "%zu position values (need a non-empty multiple of 3)", npos);
  if (ntri_idx == 0 || ntri_idx % 3)
    return verr_set(err, "%zu triangle indices (need a non-empty multiple of 3)", ntri_idx);
  size_t nverts = npos / 3, ntris = ntri_idx / 3;
  if (nverts > ORGAN_MAX_VERTS || ntris > ORGAN_MAX_TRIS)
    return verr_set(err, "%zu vertices, %zu triangles exceed the viewer's limit (%u, %u)", nverts, ntris,
                    ORGAN_MAX_VERTS, ORGAN_MAX_TRIS);
  for (size_t i = 0; i < npos; i++)
    if (!isfinite(pos[i])) return verr_set(err, "vertex %zu has a non-finite coordinate (%g)", i / 3, (double)pos[i]);
  for (size_t i = 0; i < ntri_idx; i++)
    if (tris[i] >= nverts)
      return verr_set(err, "triangle %zu references vertex %u but the keyframe has %zu vertices", i / 3, tris[i],
                      nverts);

  /* Allocate everything before touching the state, so a failure keeps it. */
  float *key = malloc(npos * sizeof *key), *cur = malloc(npos * sizeof *cur), *scratch = malloc(npos * sizeof *scratch);
  uint32_t *t = malloc(ntri_idx * sizeof *t);
  if (!key || !cur || !scratch || !t) {
    free(key), free(cur), free(scratch), free(t);
    return verr_set(err, "out of memory for a keyframe of %zu vertices", nverts);
  }
  memcpy(key, pos, npos * sizeof *key);
  memcpy(cur, pos, npos * sizeof *cur);
  memcpy(t, tris, ntri_idx * sizeof *t);
  free(o->key), free(o->cur), free(o->scratch), free(o->tris);
  o->key = key, o->cur = cur, o->scratch = scratch, o->tris = t;
  o->nverts = nverts, o->ntris = ntris;
  o->have_key = 1;
  o->topology_version = topology_version;
  o->keyframe_seq = keyframe_seq;
  o->sim_time_ns = sim_time_ns;
  o->applied = 0;
  /* A kept delta for an older keyframe (e.g. the topology before) will never apply. */
  if (o->have_delta && cmp_key(o, o->delta.topology_version, o->delta.keyframe_seq) < 0) o->have_delta = 0;
  if (delta_matches(o) && apply_kept_delta(o, err)) return 1;
  return 0;
}

int organ_state_delta(organ_state_t *o, const organ_delta_t *d, verr_t *err) {
  /* Shape checks before copying; mesh_delta_apply checks indices against
   * the keyframe when it applies. */
  if (d->count > ORGAN_MAX_VERTS)
    return verr_set(err, "delta lists %zu vertices (limit %u)", d->count, ORGAN_MAX_VERTS);
  if (d->dq_len != 3 * d->count)
    return verr_set(err, "delta has %zu indices but %zu components (expected %zu)", d->count, d->dq_len, 3 * d->count);
  if (!(d->quant_step > 0) || !isfinite(d->quant_step))
    return verr_set(err, "delta quant_step %g is not a positive finite number", (double)d->quant_step);
  /* Encoded against a keyframe older than the drawn one: its indices may
   * name other vertices now. Ignored, and a delta kept for a newer keyframe
   * stays. */
  if (o->have_key && cmp_key(o, d->topology_version, d->keyframe_seq) < 0) return 2;
  if (d->count > o->delta_cap) {
    uint32_t *idx = realloc(o->delta_idx, d->count * sizeof *idx);
    if (idx) o->delta_idx = idx;
    int16_t *dq = idx ? realloc(o->delta_dq, 3 * d->count * sizeof *dq) : NULL;
    if (dq) o->delta_dq = dq;
    if (!idx || !dq) return verr_set(err, "out of memory for a delta of %zu vertices", d->count);
    o->delta_cap = d->count;
  }
  if (d->count) {
    memcpy(o->delta_idx, d->indices, d->count * sizeof *o->delta_idx);
    memcpy(o->delta_dq, d->dq, 3 * d->count * sizeof *o->delta_dq);
  }
  o->delta = *d;
  o->delta.indices = o->delta_idx;
  o->delta.dq = o->delta_dq;
  o->have_delta = 1;
  if (!delta_matches(o)) return 0;
  return apply_kept_delta(o, err) ? -1 : 1;
}

long long organ_state_frame_seq(const organ_state_t *o) { return o->applied ? (long long)o->applied_frame_seq : -1; }

void organ_state_free(organ_state_t *o) {
  free(o->key), free(o->cur), free(o->scratch), free(o->tris);
  free(o->delta_idx), free(o->delta_dq);
  memset(o, 0, sizeof *o);
}
