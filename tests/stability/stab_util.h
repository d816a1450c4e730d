/* SPDX-License-Identifier: Apache-2.0 */
/* stab_util.h: small meshes and model construction shared by the stability
 * tests (docs/numerics.md §5). Header-only; each test is one executable. */
#ifndef VISCERA_STAB_UTIL_H
#define VISCERA_STAB_UTIL_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "physics/model.h"
#include "scene.h"
#include "test_rng.h"
#include "vmath.h"

/* An organ entry with the scene parser's defaults plus `extra` (YAML lines
 * indented by 4), so tests get exactly what a scene file would give. */
static inline scene_organ_t stab_organ(const char *extra) {
  static scene_t sc;
  char yaml[2048];
  verr_t err;
  snprintf(yaml, sizeof yaml, "scene: stability\norgans:\n  - name: tissue\n    mesh: none.obj\n%s", extra);
  if (scene_load_string(yaml, "stability.yaml", NULL, &sc, &err)) {
    fprintf(stderr, "stab_organ: %s\n", err.msg);
    exit(2);
  }
  return sc.organs[0];
}

static inline model_t *stab_model(const scene_organ_t *cfg, const mesh_t *surface, const double g[3], double dt,
                                  verr_t *err) {
  model_params_t p = {.cfg = cfg, .surface = surface, .dt = dt, .tool_stiffness = 0};
  if (g) v3_copy(p.gravity, g);
  return model_create(&p, err);
}

static inline int stab_finite(const double *a, size_t n) {
  for (size_t i = 0; i < n; i++)
    if (!isfinite(a[i])) return 0;
  return 1;
}

static unsigned stab_seed = 12345;
static inline double stab_rand(void) { return test_rng_lcg(&stab_seed) - 0.5; } /* uniform in [-0.5, 0.5) */

static inline void stab_octahedron(mesh_t *m, double r) {
  static const double P[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  static const uint32_t T[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                   {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  mesh_alloc(m, 6, 8, NULL);
  for (int i = 0; i < 6; i++)
    for (int k = 0; k < 3; k++) m->pos[3 * i + k] = r * P[i][k];
  memcpy(m->tris, T, sizeof T);
}

/* A flat n x n grid of spacing h in the x-y plane at z = 0, two triangles
 * per cell alternating diagonals. */
static inline void stab_grid(mesh_t *m, int n, double h) {
  mesh_alloc(m, (size_t)(n * n), (size_t)(2 * (n - 1) * (n - 1)), NULL);
  for (int j = 0; j < n; j++)
    for (int i = 0; i < n; i++) v3_set(m->pos + 3 * (size_t)(j * n + i), i * h, j * h, 0);
  size_t t = 0;
  for (int j = 0; j + 1 < n; j++)
    for (int i = 0; i + 1 < n; i++) {
      uint32_t a = (uint32_t)(j * n + i), b = a + 1, c = a + (uint32_t)n, d = c + 1;
      uint32_t *q = m->tris + 6 * t++;
      if ((i + j) % 2) {
        q[0] = a, q[1] = b, q[2] = d, q[3] = a, q[4] = d, q[5] = c;
      } else {
        q[0] = a, q[1] = b, q[2] = c, q[3] = b, q[4] = d, q[5] = c;
      }
    }
}

/* Closed box surface [0,sx] x [0,sy] x [0,sz], each face a grid of
 * nx x ny x nz cells, outward oriented (vertices on edges are shared). */
static inline void stab_box(mesh_t *m, int nx, int ny, int nz, double sx, double sy, double sz) {
  int n[3] = {nx, ny, nz};
  double s[3] = {sx, sy, sz};
  size_t nv = (size_t)(nx + 1) * (ny + 1) * (nz + 1);
  /* Index every lattice point; keep only the ones on the boundary. */
  uint32_t *id = malloc(nv * sizeof(uint32_t));
  size_t count = 0;
  for (int k = 0; k <= nz; k++)
    for (int j = 0; j <= ny; j++)
      for (int i = 0; i <= nx; i++) {
        size_t g = ((size_t)k * (ny + 1) + j) * (nx + 1) + i;
        int on = i == 0 || i == nx || j == 0 || j == ny || k == 0 || k == nz;
        id[g] = on ? (uint32_t)count++ : UINT32_MAX;
      }
  size_t ntris = 4 * ((size_t)nx * ny + (size_t)ny * nz + (size_t)nx * nz);
  mesh_alloc(m, count, ntris, NULL);
  for (int k = 0; k <= nz; k++)
    for (int j = 0; j <= ny; j++)
      for (int i = 0; i <= nx; i++) {
        size_t g = ((size_t)k * (ny + 1) + j) * (nx + 1) + i;
        if (id[g] != UINT32_MAX) v3_set(m->pos + 3 * (size_t)id[g], s[0] * i / nx, s[1] * j / ny, s[2] * k / nz);
      }
  size_t t = 0;
  /* For each axis a and side (0 or n[a]) a grid over the other two axes b, c
   * with (a, b, c) cyclic, so (b x c) = +a: side n[a] keeps that order. */
  for (int a = 0; a < 3; a++) {
    int b = (a + 1) % 3, c = (a + 2) % 3;
    for (int side = 0; side < 2; side++)
      for (int u = 0; u < n[b]; u++)
        for (int w = 0; w < n[c]; w++) {
          uint32_t q[4];
          for (int corner = 0; corner < 4; corner++) {
            int p[3];
            p[a] = side ? n[a] : 0;
            p[b] = u + (corner == 1 || corner == 2);
            p[c] = w + (corner >= 2);
            q[corner] = id[((size_t)p[2] * (ny + 1) + p[1]) * (nx + 1) + p[0]];
          }
          /* q: (u,w) (u+1,w) (u+1,w+1) (u,w+1), counter-clockwise about +a */
          uint32_t *tr = m->tris + 3 * t;
          if (side) {
            tr[0] = q[0], tr[1] = q[1], tr[2] = q[2], tr[3] = q[0], tr[4] = q[2], tr[5] = q[3];
          } else {
            tr[0] = q[0], tr[1] = q[2], tr[2] = q[1], tr[3] = q[0], tr[4] = q[3], tr[5] = q[2];
          }
          t += 2;
        }
  }
  free(id);
}

#endif
