/* SPDX-License-Identifier: Apache-2.0 */
#include "session/mesh_publisher.h"

#include <stdlib.h>
#include <string.h>

#include "dds/key_chunks.h"
#include "mesh_delta.h"
#include "viscera.h"
#include "vtime.h"

/* Buffers for at least n vertices; keeps the contents' prefix. */
static int grow(mesh_publisher_t *mp, size_t n) {
  if (mp->key && n <= mp->cap_verts) return 0;
  float *key = realloc(mp->key, (3 * n + 1) * sizeof *key);
  if (key) mp->key = key;
  uint32_t *idx = realloc(mp->idx, (n + 1) * sizeof *idx);
  if (idx) mp->idx = idx;
  int16_t *dq = realloc(mp->dq, (3 * n + 1) * sizeof *dq);
  if (dq) mp->dq = dq;
  uint32_t *widx = realloc(mp->written_idx, (n + 1) * sizeof *widx);
  if (widx) mp->written_idx = widx;
  int16_t *wdq = realloc(mp->written_dq, (3 * n + 1) * sizeof *wdq);
  if (wdq) mp->written_dq = wdq;
  if (!key || !idx || !dq || !widx || !wdq) return -1;
  mp->cap_verts = n;
  return 0;
}

int mesh_publisher_init(mesh_publisher_t *mp, uint32_t organ_id, size_t nverts, const uint32_t *tris, size_t ntris,
                        float quant, dds_entity_t w_state, dds_entity_t w_delta, verr_t *err) {
  memset(mp, 0, sizeof *mp);
  mp->organ_id = organ_id;
  mp->nverts = nverts;
  mp->tris = tris;
  mp->ntris = ntris;
  mp->quant = quant;
  mp->w_state = w_state;
  mp->w_delta = w_delta;
  if (grow(mp, nverts)) {
    mesh_publisher_destroy(mp);
    return verr_set(err, "mesh publisher: out of memory for %zu vertices", nverts);
  }
  return 0;
}

void mesh_publisher_destroy(mesh_publisher_t *mp) {
  free(mp->key);
  free(mp->chunk_blob);
  free(mp->idx);
  free(mp->dq);
  free(mp->written_idx);
  free(mp->written_dq);
  memset(mp, 0, sizeof *mp);
}

/* The current keyframe as chunks. A failure (a keyframe too large for the
 * chunks, out of memory) is counted and leaves MeshState alone to carry it. */
static int write_chunks(mesh_publisher_t *mp, uint64_t sim_time_ns) {
  verr_t err;
  if (!mp->chunk_blob && key_encode(mp->key, mp->nverts, mp->tris, mp->ntris, MESH_PUBLISHER_CHUNK_LEVEL,
                                    &mp->chunk_blob, &mp->chunk_len, &err)) {
    mp->chunk_blob = NULL;
    mp->chunk_failures++;
    return 0;
  }
  size_t len = mp->chunk_len;
  int n =
      key_chunks_write(mp->w_chunk, mp->organ_id, mp->topology_version, mp->keyframe_seq, sim_time_ns, mp->chunk_blob,
                       len, mp->chunk_copies ? mp->chunk_copies : KEY_CHUNK_COPIES, &mp->chunks_written, &err);
  if (n < 0) {
    mp->chunk_failures++;
    return 0;
  }
  mp->key_sim_time_ns = sim_time_ns;
  mp->chunk_sets++;
  mp->chunk_samples += (uint64_t)n;
  mp->chunk_payload_bytes += len;
  return 0;
}

int mesh_publisher_rechunk(mesh_publisher_t *mp) {
  if (mp->broken || !mp->w_chunk || !mp->keyframe_seq || !mp->chunks_written) return -1;
  uint64_t sets = mp->chunk_sets;
  write_chunks(mp, mp->key_sim_time_ns);
  if (mp->chunk_sets == sets) return -1;
  mp->chunk_sets = sets;
  mp->chunk_rewrites++;
  return 0;
}

int mesh_publisher_keyframe(mesh_publisher_t *mp, const double *x, uint64_t sim_time_ns) {
  if (mp->broken) return -1;
  for (size_t i = 0; i < 3 * mp->nverts; i++) mp->key[i] = (float)x[i];
  free(mp->chunk_blob); /* a new keyframe: its chunks are encoded anew */
  mp->chunk_blob = NULL;
  mp->keyframe_seq++;
  mp->keyframes++;
  mp->keyframe_payload_bytes += mesh_publisher_keyframe_bytes(mp);
  mp->last_count = 0;
  mp->have_written = 0; /* deltas of a new keyframe are new samples */
  if (!mp->w_state) return 0;
  viscera_MeshState s;
  memset(&s, 0, sizeof s);
  s.organ_id = mp->organ_id;
  s.topology_version = mp->topology_version;
  s.keyframe_seq = mp->keyframe_seq;
  s.sim_time_ns = sim_time_ns;
  s.positions._buffer = mp->key;
  s.positions._length = s.positions._maximum = (uint32_t)(3 * mp->nverts);
  s.triangles._buffer = (uint32_t *)mp->tris;
  s.triangles._length = s.triangles._maximum = (uint32_t)(3 * mp->ntris);
  dds_return_t rc = dds_write(mp->w_state, &s);
  if (rc < 0) return -1;
  return mp->w_chunk ? write_chunks(mp, sim_time_ns) : 0;
}

int mesh_publisher_frame(mesh_publisher_t *mp, const double *x, uint64_t sim_time_ns) {
  if (mp->broken) return -1;
  long n = mesh_delta_encode(mp->key, x, mp->nverts, mp->quant, mp->idx, mp->dq);
  int keyed = 0;
  if (n < 0) {
    if (mesh_publisher_keyframe(mp, x, sim_time_ns) < 0) return -1;
    n = 0;
    keyed = 1;
  }
  uint64_t now = mp->keepalive_ns ? vtime_mono_ns() : 0;
  if (mp->keepalive_ns && !keyed && mp->have_written && n == mp->written_count &&
      now - mp->written_ns < mp->keepalive_ns && !memcmp(mp->idx, mp->written_idx, (size_t)n * sizeof *mp->idx) &&
      !memcmp(mp->dq, mp->written_dq, 3 * (size_t)n * sizeof *mp->dq)) {
    mp->skipped++;
    return 0;
  }
  if (mp->keepalive_ns) {
    memcpy(mp->written_idx, mp->idx, (size_t)n * sizeof *mp->idx);
    memcpy(mp->written_dq, mp->dq, 3 * (size_t)n * sizeof *mp->dq);
    mp->written_count = n;
    mp->written_ns = now;
    mp->have_written = 1;
  }
  mp->frame_seq++;
  mp->frames++;
  mp->last_count = n;
  mp->delta_payload_bytes += mesh_publisher_last_delta_bytes(mp);
  if (!mp->w_delta) return keyed;
  viscera_MeshDelta d;
  memset(&d, 0, sizeof d);
  d.organ_id = mp->organ_id;
  d.topology_version = mp->topology_version;
  d.keyframe_seq = mp->keyframe_seq;
  d.frame_seq = mp->frame_seq;
  d.sim_time_ns = sim_time_ns;
  d.quant_step = mp->quant;
  d.indices._buffer = mp->idx;
  d.indices._length = d.indices._maximum = (uint32_t)n;
  d.dq._buffer = mp->dq;
  d.dq._length = d.dq._maximum = (uint32_t)(3 * n);
  return dds_write(mp->w_delta, &d) < 0 ? -1 : keyed;
}

size_t mesh_publisher_last_delta_bytes(const mesh_publisher_t *mp) {
  /* 5 x uint32 + uint64 + float, two sequence lengths, then the payload
   * (CDR pads the int16 sequence to 4 bytes at most). */
  size_t n = (size_t)(mp->last_count > 0 ? mp->last_count : 0);
  return 5 * 4 + 8 + 4 + 2 * 4 + n * 4 + n * 6;
}

size_t mesh_publisher_keyframe_bytes(const mesh_publisher_t *mp) {
  /* 3 x uint32 key and versions, uint64 time, two sequence lengths, payload. */
  return 3 * 4 + 8 + 2 * 4 + mp->nverts * 3 * 4 + mp->ntris * 3 * 4;
}

int mesh_publisher_retopo(mesh_publisher_t *mp, uint32_t model_version, size_t nverts, const uint32_t *tris,
                          size_t ntris, const double *x, uint64_t sim_time_ns, verr_t *err) {
  for (size_t i = 0; i < 3 * ntris; i++)
    if (tris[i] >= nverts) {
      mp->broken = 1;
      return verr_set(err, "mesh publisher: organ %u topology %u: triangle %zu uses vertex %u of %zu; publishing stops",
                      mp->organ_id, model_version, i / 3, tris[i], nverts);
    }
  if (nverts == 0 || ntris == 0 || grow(mp, nverts)) {
    mp->broken = 1;
    return verr_set(err, "mesh publisher: organ %u: %s for a surface of %zu vertices, %zu triangles; publishing stops",
                    mp->organ_id, nverts && ntris ? "out of memory" : "empty surface", nverts, ntris);
  }
  mp->nverts = nverts;
  mp->ntris = ntris;
  mp->tris = tris;
  mp->model_version = model_version;
  mp->topology_version++;
  mp->retopos++;
  if (mesh_publisher_keyframe(mp, x, sim_time_ns) < 0)
    return verr_set(err, "mesh publisher: organ %u: writing the topology %u keyframe failed", mp->organ_id,
                    mp->topology_version);
  return 0;
}
