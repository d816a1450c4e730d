#include "mesh_publisher.h"

#include <stdlib.h>
#include <string.h>

#include "mesh_delta.h"
#include "viscera.h"

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
  mp->key = calloc(3 * nverts + 1, sizeof(float));
  mp->idx = calloc(nverts + 1, sizeof(uint32_t));
  mp->dq = calloc(3 * nverts + 1, sizeof(int16_t));
  if (!mp->key || !mp->idx || !mp->dq) {
    mesh_publisher_destroy(mp);
    return verr_set(err, "mesh publisher: out of memory for %zu vertices", nverts);
  }
  return 0;
}

void mesh_publisher_destroy(mesh_publisher_t *mp) {
  free(mp->key);
  free(mp->idx);
  free(mp->dq);
  memset(mp, 0, sizeof *mp);
}

int mesh_publisher_keyframe(mesh_publisher_t *mp, const double *x, uint64_t sim_time_ns) {
  for (size_t i = 0; i < 3 * mp->nverts; i++) mp->key[i] = (float)x[i];
  mp->keyframe_seq++;
  mp->keyframes++;
  mp->last_count = 0;
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
  return rc < 0 ? -1 : 0;
}

int mesh_publisher_frame(mesh_publisher_t *mp, const double *x, uint64_t sim_time_ns) {
  long n = mesh_delta_encode(mp->key, x, mp->nverts, mp->quant, mp->idx, mp->dq);
  int keyed = 0;
  if (n < 0) {
    if (mesh_publisher_keyframe(mp, x, sim_time_ns) < 0) return -1;
    n = 0;
    keyed = 1;
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
