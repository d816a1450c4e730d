/* SPDX-License-Identifier: Apache-2.0 */
/* mesh_publisher_retopo in encode-only mode (no DDS writers): a topology
 * change adopts the new arrays and counts, grows the buffers, moves
 * topology_version and keyframe_seq on, keyframes the new positions at once,
 * and the next delta is encoded against that keyframe and decodes to the new
 * mesh; shrinking keeps the buffers; a bad surface stops publishing. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "mesh_delta.h"
#include "session/mesh_publisher.h"

#define Q 1e-5f

/* A strip of n vertices along x (two rows), 2 (n/2 - 1) triangles. */
static void strip(size_t n, double *x, uint32_t *tris, size_t *ntris) {
  for (size_t i = 0; i < n; i++) {
    x[3 * i] = 0.01 * (double)(i / 2);
    x[3 * i + 1] = 0.01 * (double)(i % 2);
    x[3 * i + 2] = 0;
  }
  size_t t = 0;
  for (size_t i = 0; i + 2 < n; i += 2) {
    uint32_t a = (uint32_t)i;
    tris[3 * t] = a, tris[3 * t + 1] = a + 2, tris[3 * t + 2] = a + 1, t++;
    if (i + 3 < n) tris[3 * t] = a + 1, tris[3 * t + 1] = a + 2, tris[3 * t + 2] = a + 3, t++;
  }
  *ntris = t;
}

/* The mesh a receiver rebuilds from the last keyframe plus the last delta. */
static int decoded_matches(const mesh_publisher_t *mp, const double *x, size_t n) {
  float *out = malloc(3 * n * sizeof *out);
  verr_t err;
  int ok = out && mesh_delta_apply(mp->key, mp->nverts, mp->quant, mp->idx, (size_t)mp->last_count, mp->dq,
                                   3 * (size_t)mp->last_count, out, &err) == 0;
  for (size_t i = 0; ok && i < 3 * n; i++) ok = fabs((double)out[i] - x[i]) <= 0.5 * Q + 1e-7;
  free(out);
  return ok;
}

int main(void) {
  enum { N0 = 8, N1 = 40 };
  double x0[3 * N0], x1[3 * N1];
  uint32_t t0[3 * 2 * N0], t1[3 * 2 * N1];
  size_t nt0, nt1;
  strip(N0, x0, t0, &nt0);
  strip(N1, x1, t1, &nt1);
  mesh_publisher_t mp;
  verr_t err;
  CHECK(mesh_publisher_init(&mp, 3, N0, t0, nt0, Q, 0, 0, &err) == 0);
  CHECK(mesh_publisher_keyframe(&mp, x0, 0) == 0);
  CHECK(mp.topology_version == 0 && mp.keyframe_seq == 1 && mp.cap_verts == N0);
  x0[3 * 5 + 2] = 2e-4;
  CHECK(mesh_publisher_frame(&mp, x0, 1) == 0 && mp.last_count == 1 && mp.idx[0] == 5);
  CHECK(decoded_matches(&mp, x0, N0));
  size_t kb0 = mesh_publisher_keyframe_bytes(&mp);
  CHECK(kb0 == 28 + 12 * N0 + 12 * nt0);

  /* Grow: 8 -> 40 vertices. */
  uint64_t key_before = mp.keyframes;
  x1[3 * 30 + 1] += 1e-3; /* the new surface is deformed already */
  CHECK(mesh_publisher_retopo(&mp, 7, N1, t1, nt1, x1, 2, &err) == 0);
  CHECK(mp.topology_version == 1 && mp.model_version == 7 && mp.keyframe_seq == 2 && mp.keyframes == key_before + 1);
  CHECK(mp.nverts == N1 && mp.ntris == nt1 && mp.tris == t1 && mp.cap_verts >= N1 && mp.retopos == 1);
  int key_ok = 1;
  for (size_t i = 0; i < 3 * N1; i++) key_ok &= mp.key[i] == (float)x1[i];
  CHECK(key_ok);
  CHECK(mp.keyframe_payload_bytes == kb0 + mesh_publisher_keyframe_bytes(&mp));
  /* The next delta is against the new keyframe: a vertex beyond the old
   * count moves, and keyframe + delta is the new mesh. */
  x1[3 * 39] += 3e-4;
  CHECK(mesh_publisher_frame(&mp, x1, 3) == 0 && mp.last_count == 1 && mp.idx[0] == 39);
  CHECK(mp.dq[0] == 30 && decoded_matches(&mp, x1, N1));

  /* Shrink: back to 8 vertices, buffers kept. */
  float *key = mp.key;
  size_t cap = mp.cap_verts;
  CHECK(mesh_publisher_retopo(&mp, 9, N0, t0, nt0, x0, 4, &err) == 0);
  CHECK(mp.topology_version == 2 && mp.keyframe_seq == 3 && mp.nverts == N0 && mp.key == key && mp.cap_verts == cap);
  CHECK(mesh_publisher_frame(&mp, x0, 5) == 0 && mp.last_count == 0 && decoded_matches(&mp, x0, N0));
  CHECK(mesh_publisher_keyframe_bytes(&mp) == kb0);

  /* A triangle beyond the vertices: refused, and the publisher stops rather
   * than send a surface the model no longer has. */
  uint32_t bad[3] = {0, 1, N0};
  CHECK(mesh_publisher_retopo(&mp, 10, N0, bad, 1, x0, 6, &err) == -1 && strstr(err.msg, "vertex 8 of 8"));
  CHECK(mp.broken && mesh_publisher_frame(&mp, x0, 7) == -1 && mesh_publisher_keyframe(&mp, x0, 7) == -1);
  CHECK(mp.topology_version == 2);
  mesh_publisher_destroy(&mp);
  return check_report("test_mesh_publisher_retopo");
}
