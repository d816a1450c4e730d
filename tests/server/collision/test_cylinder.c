/* SPDX-License-Identifier: Apache-2.0 */
/* Cylinder tool against nodes (docs/methods.md D §2.2) on hand-made cases: inside,
 * beyond either end (on the axis line but failing an angle test), on the end
 * planes, at the radius, a slanted axis, a zero-length axis, the force
 * direction N -> p; then the grid-accelerated query against the scan on a
 * random cloud and on an organ. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_rng.h"
#include "test_assets.h"
#include "collision/cylinder.h"
#include "mesh.h"
#include "mesh_import.h"
#include "vmath.h"

static uint64_t rng_state = 0x5851f42d4c957f2dull;
static double urand(void) { return test_rng_uniform(&rng_state); }

static int inside(const cylinder_t *c, double x, double y, double z) {
  cylinder_hit_t h;
  return cylinder_test_node(c, (double[]){x, y, z}, &h);
}

static void hand_cases(void) {
  /* Axis along x from 0 to 1, radius 0.1. */
  cylinder_t c = {{0, 0, 0}, {1, 0, 0}, 0.1};
  cylinder_hit_t h;
  CHECK(inside(&c, 0.5, 0.05, 0));
  CHECK(inside(&c, 0.5, 0.05, -0.05));
  CHECK(!inside(&c, 0.5, 0.2, 0));
  /* On the axis line but beyond an end: the angle tests reject it, though
   * its distance to the infinite line is zero. */
  CHECK(!inside(&c, -0.01, 0, 0));
  CHECK(!inside(&c, 1.01, 0, 0));
  CHECK(!inside(&c, 1.05, 0.01, 0)); /* within r of the end point, still beyond the end plane */
  /* On the end planes (angle exactly 90 degrees): inside. */
  CHECK(inside(&c, 0, 0.05, 0));
  CHECK(inside(&c, 1, 0, 0.05));
  /* The radius test is strict: d < r. */
  CHECK(!inside(&c, 0.5, 0.1, 0));
  CHECK(inside(&c, 0.5, nextafter(0.1, 0), 0));
  /* Hit details: t, d and the direction from N to p. */
  CHECK(cylinder_test_node(&c, (double[]){0.25, 0, 0.06}, &h));
  CHECK_NEAR(h.t, 0.25, 1e-15);
  CHECK_NEAR(h.dist, 0.06, 1e-15);
  CHECK_NEAR(h.dir[0], 0, 1e-15);
  CHECK_NEAR(h.dir[2], -1, 1e-15);
  /* A node on the axis: zero distance, zero direction (no NaN). */
  CHECK(cylinder_test_node(&c, (double[]){0.7, 0, 0}, &h));
  CHECK(h.dist == 0 && v3_norm(h.dir) == 0);
  /* Slanted axis (1,1,1)/sqrt3, length sqrt3, radius 0.2. */
  cylinder_t s = {{0, 0, 0}, {1, 1, 1}, 0.2};
  double u[3] = {1, -1, 0};
  v3_normalize(u);
  CHECK(inside(&s, 0.5 + 0.19 * u[0], 0.5 + 0.19 * u[1], 0.5));
  CHECK(!inside(&s, 0.5 + 0.21 * u[0], 0.5 + 0.21 * u[1], 0.5));
  CHECK(cylinder_test_node(&s, (double[]){0.5 + 0.1 * u[0], 0.5 + 0.1 * u[1], 0.5}, &h));
  CHECK_NEAR(h.t, 0.5, 1e-12);
  CHECK_NEAR(h.dist, 0.1, 1e-12);
  CHECK_NEAR(v3_dot(h.dir, u), -1, 1e-12);
  CHECK(!inside(&s, 1.05, 1.05, 1.05)); /* past p1 along the axis */
  CHECK(!inside(&s, -0.05, -0.05, -0.05));
  /* Near the p1 end: a point 0.1 off-axis just before the end plane is in,
   * the same just after is out. */
  CHECK(inside(&s, 0.99 + 0.1 * u[0], 0.99 + 0.1 * u[1], 0.99));
  CHECK(!inside(&s, 1.01 + 0.1 * u[0], 1.01 + 0.1 * u[1], 1.01));
  /* Zero-length axis: a sphere of radius r. */
  cylinder_t p = {{1, 2, 3}, {1, 2, 3}, 0.5};
  CHECK(inside(&p, 1.3, 2.3, 3));
  CHECK(!inside(&p, 1.4, 2.4, 3));
  /* Scan: node order, count beyond cap. */
  double x[] = {0.5, 0.05, 0, 2, 0, 0, 0.2, 0, 0.01, 0.5, 0.5, 0.5, 0.9, -0.09, 0};
  cylinder_hit_t hits[4];
  CHECK(cylinder_nodes_scan(&c, x, 5, hits, 4) == 3);
  CHECK(hits[0].node == 0 && hits[1].node == 2 && hits[2].node == 4);
  CHECK(cylinder_nodes_scan(&c, x, 5, hits, 1) == 3 && hits[0].node == 0);
}

static int cmp_hit(const void *a, const void *b) {
  uint32_t x = ((const cylinder_hit_t *)a)->node, y = ((const cylinder_hit_t *)b)->node;
  return (x > y) - (x < y);
}

/* Grid query == scan (same nodes, same t and d) for random tools. */
static void grid_vs_scan(const char *what, const double *x, size_t n, double size, int ntools) {
  node_grid_t g;
  verr_t err;
  CHECK(node_grid_create(&g, x, n, 0, &err) == 0);
  cylinder_hit_t *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b);
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < n; i++)
    for (int k = 0; k < 3; k++) {
      lo[k] = fmin(lo[k], x[3 * i + (size_t)k]);
      hi[k] = fmax(hi[k], x[3 * i + (size_t)k]);
    }
  int fails = 0;
  size_t total = 0;
  for (int i = 0; i < ntools; i++) {
    cylinder_t c;
    for (int k = 0; k < 3; k++) {
      c.p0[k] = lo[k] + (hi[k] - lo[k]) * urand();
      c.p1[k] = c.p0[k] + size * (2 * urand() - 1);
    }
    c.radius = size * (0.02 + 0.2 * urand());
    size_t na = cylinder_nodes_grid(&c, &g, a, n), nb = cylinder_nodes_scan(&c, x, n, b, n);
    qsort(a, na, sizeof *a, cmp_hit);
    int bad = na != nb;
    for (size_t j = 0; !bad && j < na; j++) bad = a[j].node != b[j].node || a[j].t != b[j].t || a[j].dist != b[j].dist;
    /* Every reported node really is within r of the segment, and every
     * other node is not (independent of the angle formulation: the
     * distance to the segment, clamped projection). */
    for (size_t v = 0; v < n; v++) {
      double ax[3], d[3];
      v3_sub(ax, c.p1, c.p0);
      v3_sub(d, x + 3 * v, c.p0);
      double l2 = v3_dot(ax, ax), t = l2 > 0 ? v3_dot(d, ax) / l2 : 0;
      double foot[3];
      v3_copy(foot, c.p0);
      v3_axpy(foot, ax, fmin(1, fmax(0, t)));
      double dist = v3_dist(foot, x + 3 * v);
      int in = 0;
      for (size_t j = 0; j < nb; j++) in |= b[j].node == v;
      /* Off the ends the seed's cylinder is flat-capped, the clamped
       * distance is a capsule: they agree between the end planes. */
      if (t >= 1e-9 && t <= 1 - 1e-9 && fabs(dist - c.radius) > 1e-12 * size) bad |= in != (dist < c.radius);
      if (t < -1e-9 || t > 1 + 1e-9) bad |= in;
    }
    total += nb;
    if (bad && fails++ < 3) fprintf(stderr, "%s tool %d: grid %zu scan %zu\n", what, i, na, nb);
  }
  printf("%s: %d tools, %zu node hits compared\n", what, ntools, total);
  CHECK(fails == 0);
  CHECK(total > (size_t)ntools); /* not vacuous */
  free(a);
  free(b);
  node_grid_destroy(&g);
}

int main(void) {
  hand_cases();
  enum { N = 3000 };
  double *cloud = malloc(3 * N * sizeof *cloud);
  for (int i = 0; i < 3 * N; i++) cloud[i] = 0.1 * urand();
  grid_vs_scan("random cloud", cloud, N, 0.05, 300);
  free(cloud);
  const char *dir = getenv("VISCERA_SOURCE_DIR");
  if (!dir) {
    fprintf(stderr, "test_cylinder: VISCERA_SOURCE_DIR not set; skipping the organ mesh\n");
    check_report("test_cylinder");
    return 77;
  }
  mesh_t m;
  if (test_mesh_load("kidney.obj", &m)) {
    CHECK(0);
  } else {
    grid_vs_scan("kidney", m.pos, m.nverts, 0.06, 300);
    mesh_free(&m);
  }
  return check_report("test_cylinder");
}
