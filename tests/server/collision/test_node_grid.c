/* SPDX-License-Identifier: Apache-2.0 */
/* node_grid against a linear scan (the thesis's "linear method", docs/methods.md B
 * Table 4.1): the nearest node (same id, same squared distance, ties to the
 * lowest id) for points on, near, inside, around and far from the organ
 * meshes, and the nodes in random boxes; again after large motion and a
 * rebuild (spreading out, which coarsens the cells, and shrinking back), on a
 * flat patch, on a lattice where queries tie exactly, with non-finite nodes
 * and with no nodes. Skips (77) without VISCERA_SOURCE_DIR. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_rng.h"
#include "test_assets.h"
#include "collision/node_grid.h"
#include "mesh.h"
#include "mesh_import.h"
#include "vmath.h"

static uint64_t rng_state = 0x2545f4914f6cdd1dull;
static double urand(void) { return test_rng_uniform(&rng_state); }
static double srand1(void) { return 2 * urand() - 1; }

static uint32_t scan_nearest(const double *x, size_t n, const double q[3], double *d2out) {
  double best = INFINITY;
  uint32_t id = NODE_GRID_NONE;
  for (size_t i = 0; i < n; i++) {
    const double *p = x + 3 * i;
    if (!(fabs(p[0]) < 1e100 && fabs(p[1]) < 1e100 && fabs(p[2]) < 1e100)) continue;
    double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2], d2 = dx * dx + dy * dy + dz * dz;
    if (d2 < best) {
      best = d2;
      id = (uint32_t)i;
    }
  }
  *d2out = best;
  return id;
}

static int cmp_u32(const void *a, const void *b) {
  uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
  return (x > y) - (x < y);
}

static void compare(const char *what, const node_grid_t *g, const double *x, size_t n, int nq) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < n; i++)
    for (int k = 0; k < 3; k++)
      if (fabs(x[3 * i + (size_t)k]) < 1e100) {
        lo[k] = fmin(lo[k], x[3 * i + (size_t)k]);
        hi[k] = fmax(hi[k], x[3 * i + (size_t)k]);
      }
  double diag = v3_dist(lo, hi);
  uint32_t *got = malloc((n + 1) * sizeof *got), *want = malloc((n + 1) * sizeof *want);
  int fail_near = 0, fail_box = 0;
  size_t boxed = 0;
  for (int i = 0; i < nq; i++) {
    double q[3];
    int kind = i % 4;
    if (kind == 0) { /* near a node: the touched-node case */
      size_t j = (size_t)(urand() * (double)n);
      for (int k = 0; k < 3; k++) q[k] = x[3 * j + (size_t)k] + 0.01 * diag * srand1();
      for (int k = 0; k < 3; k++)
        if (!(fabs(q[k]) < 1e100)) q[k] = 0;
    } else if (kind == 1) { /* anywhere in and around the box */
      for (int k = 0; k < 3; k++) q[k] = lo[k] + (hi[k] - lo[k]) * (1.4 * urand() - 0.2);
    } else if (kind == 2) { /* outside on one side, within the grid's span on the others */
      for (int k = 0; k < 3; k++) q[k] = lo[k] + (hi[k] - lo[k]) * urand();
      q[i % 3] = (i & 4) ? hi[i % 3] + diag * urand() : lo[i % 3] - diag * urand();
    } else { /* far away */
      for (int k = 0; k < 3; k++) q[k] = 0.5 * (lo[k] + hi[k]) + 20 * diag * srand1();
    }
    double dg, ds;
    uint32_t a = node_grid_nearest(g, q, &dg), b = scan_nearest(x, n, q, &ds);
    if ((a != b || dg != ds) && fail_near++ < 3)
      fprintf(stderr, "%s nearest %d: grid %u d2 %.17g, scan %u d2 %.17g\n", what, i, a, dg, b, ds);
    /* Boxes around random nodes. */
    double c[3], bl[3], bh[3], size = diag * 0.15 * urand();
    size_t j = (size_t)(urand() * (double)n);
    for (int k = 0; k < 3; k++) c[k] = fabs(x[3 * j]) < 1e100 ? x[3 * j + (size_t)k] : 0;
    for (int k = 0; k < 3; k++) {
      bl[k] = c[k] - size * urand();
      bh[k] = c[k] + size * urand();
    }
    size_t n1 = node_grid_query_box(g, bl, bh, got, n), n2 = 0;
    for (size_t v = 0; v < n; v++) {
      const double *p = x + 3 * v;
      if (!(fabs(p[0]) < 1e100 && fabs(p[1]) < 1e100 && fabs(p[2]) < 1e100)) continue; /* left out of the grid */
      if (p[0] >= bl[0] && p[0] <= bh[0] && p[1] >= bl[1] && p[1] <= bh[1] && p[2] >= bl[2] && p[2] <= bh[2])
        want[n2++] = (uint32_t)v;
    }
    qsort(got, n1 < n ? n1 : n, sizeof *got, cmp_u32);
    int bad = n1 != n2 || memcmp(got, want, n1 * sizeof *got);
    if (n2 > 1) bad |= node_grid_query_box(g, bl, bh, got, 1) != n2;
    if (bad && fail_box++ < 3) fprintf(stderr, "%s box %d: grid %zu scan %zu\n", what, i, n1, n2);
    boxed += n2;
  }
  CHECK(fail_near == 0);
  CHECK(fail_box == 0);
  CHECK(boxed > (size_t)nq); /* not vacuous */
  free(got);
  free(want);
}

static void organ(const char *dir, const char *name, int nq) {
  (void)dir; /* the support library finds the assets */
  mesh_t m;
  verr_t err;
  if (test_organ_load(name, &m)) {
    CHECK(0);
    return;
  }
  node_grid_t g;
  CHECK(node_grid_create(&g, m.pos, m.nverts, 0, &err) == 0);
  size_t occupied = 0;
  for (size_t c = 0; c < g.ncells; c++) occupied += g.cell_start[c + 1] > g.cell_start[c];
  printf("%s: %zu nodes, cell %.2f mm, %u x %u x %u cells, %zu occupied (%.1f nodes each)\n", name, m.nverts,
         1e3 * g.cell, g.dims[0], g.dims[1], g.dims[2], occupied, (double)m.nverts / (double)occupied);
  CHECK(g.ninside == m.nverts);
  char what[128];
  snprintf(what, sizeof what, "%s rest", name);
  compare(what, &g, m.pos, m.nverts, nq);
  double *x = malloc(3 * m.nverts * sizeof *x);
  /* Deformed in place (a tool pressing and pulling), then spread to 3x
   * (beyond the reserved cells: the rebuild must coarsen, not allocate), then
   * shrunk to a quarter. */
  for (int round = 0; round < 3; round++) {
    double scale = round == 0 ? 1.0 : round == 1 ? 3.0 : 0.25;
    for (size_t i = 0; i < m.nverts; i++) {
      const double *p = m.pos + 3 * i;
      x[3 * i] = scale * p[0] + 0.01 * sin(40 * p[1]);
      x[3 * i + 1] = scale * p[1] + 0.01 * sin(30 * p[2] + 1);
      x[3 * i + 2] = scale * p[2] - 0.015 * exp(-300 * (p[0] * p[0] + p[1] * p[1]));
    }
    node_grid_rebuild(&g, x);
    if (round == 1) CHECK(g.cell > g.cell0);
    if (round == 2) CHECK(g.cell == g.cell0);
    CHECK(g.ncells <= g.cap_cells);
    snprintf(what, sizeof what, "%s moved %d", name, round);
    compare(what, &g, x, m.nverts, nq / 2);
  }
  /* Non-finite nodes are left out and never returned. */
  memcpy(x, m.pos, 3 * m.nverts * sizeof *x);
  x[0] = NAN;
  x[4] = INFINITY;
  x[3 * (m.nverts / 2) + 2] = 1e200;
  node_grid_rebuild(&g, x);
  CHECK(g.ninside == m.nverts - 3);
  snprintf(what, sizeof what, "%s non-finite", name);
  compare(what, &g, x, m.nverts, nq / 4);
  free(x);
  node_grid_destroy(&g);
  mesh_free(&m);
}

/* Integer lattice with cell size 1: nodes sit exactly on cell walls and
 * queries at half-integers tie between up to eight nodes. */
static void lattice(void) {
  enum { N = 7 };
  double x[3 * N * N * N];
  size_t n = 0;
  /* Ids in a scrambled order so "lowest id" differs from "first in the cell". */
  for (int i = 0; i < N * N * N; i++) {
    int c = (i * 97) % (N * N * N);
    x[3 * n] = c % N;
    x[3 * n + 1] = (c / N) % N;
    x[3 * n + 2] = c / (N * N);
    n++;
  }
  node_grid_t g;
  verr_t err;
  CHECK(node_grid_create(&g, x, n, 1.0, &err) == 0);
  int fails = 0;
  for (int k = 0; k < 2000; k++) {
    double q[3];
    for (int a = 0; a < 3; a++) q[a] = 0.5 * floor(urand() * (2 * N + 6)) - 1.5;
    double dg, ds;
    uint32_t a = node_grid_nearest(&g, q, &dg), b = scan_nearest(x, n, q, &ds);
    fails += a != b || dg != ds;
  }
  CHECK(fails == 0);
  node_grid_destroy(&g);
}

static void edge_cases(void) {
  node_grid_t g;
  verr_t err;
  double d2;
  /* No nodes. */
  CHECK(node_grid_create(&g, NULL, 0, 0, &err) == 0);
  CHECK(node_grid_nearest(&g, (double[]){0, 0, 0}, &d2) == NODE_GRID_NONE);
  CHECK(node_grid_query_box(&g, (double[]){-1, -1, -1}, (double[]){1, 1, 1}, NULL, 0) == 0);
  node_grid_destroy(&g);
  /* One node; all nodes non-finite. */
  double one[3] = {0.1, 0.2, 0.3};
  CHECK(node_grid_create(&g, one, 1, 0, &err) == 0);
  CHECK(node_grid_nearest(&g, (double[]){5, 5, 5}, &d2) == 0);
  CHECK_NEAR(d2, 4.9 * 4.9 + 4.8 * 4.8 + 4.7 * 4.7, 1e-12);
  CHECK(node_grid_nearest(&g, (double[]){NAN, 5, 5}, &d2) == NODE_GRID_NONE && d2 == INFINITY);
  one[1] = NAN;
  node_grid_rebuild(&g, one);
  CHECK(node_grid_nearest(&g, (double[]){0, 0, 0}, &d2) == NODE_GRID_NONE);
  node_grid_destroy(&g);
  /* Coincident nodes: all in one cell, the lowest id wins. */
  double same[12] = {1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
  CHECK(node_grid_create(&g, same, 4, 0, &err) == 0);
  CHECK(node_grid_nearest(&g, (double[]){0, 0, 0}, &d2) == 0);
  node_grid_destroy(&g);
}

int main(void) {
  edge_cases();
  lattice();
  const char *dir = getenv("VISCERA_SOURCE_DIR");
  if (!dir) {
    fprintf(stderr, "test_node_grid: VISCERA_SOURCE_DIR not set; skipping the organ meshes\n");
    check_report("test_node_grid");
    return 77;
  }
  organ(dir, "tissue_block", 400); /* flat: one cell deep */
  organ(dir, "spleen", 2000);
  organ(dir, "gallbladder", 2000);
  organ(dir, "liver_large", 600);
  return check_report("test_node_grid");
}
