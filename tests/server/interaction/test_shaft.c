/* SPDX-License-Identifier: Apache-2.0 */
/* test_shaft: segment-triangle contact of tool shafts (shaft.h):
 * - on the coarse tissue_block (45 vertices, triangles ~1.7 x 1 cm) a tilted
 *   shaft whose axis crosses the middle of a triangle, every vertex far
 *   outside the cylinder: the node test alone pushes nothing, the crossing
 *   test pushes exactly that triangle's three corners, perpendicular to the
 *   axis, into the tissue, with the penalty force split by the barycentric
 *   coordinates; the tool is pushed back out; tree and scan agree to the bit;
 * - random segments through the kidney and the large liver (rest and
 *   deformed with the tree refit, or with stale boxes and the displacement
 *   as slack): the tree's crossings equal the scan's, including
 *   long segments whose pieces overflow the query buffer and are halved;
 *   contact forces equal to the bit, each vertex pushed at most once per
 *   call and never beyond SHAFT_MAX_VERTEX_FORCE (the double-push bound).
 * Skips (77) without VISCERA_SOURCE_DIR. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_assets.h"
#include "collision/aabb_tree.h"
#include "interaction/shaft.h"
#include "mesh.h"
#include "mesh_import.h"
#include "test_rng.h"
#include "vmath.h"

#define REC_MAX 4096

typedef struct rec {
  size_t n;
  uint32_t v[REC_MAX];
  double f[REC_MAX][3];
} rec_t;

static void record(void *ctx, uint32_t i, const double f[3]) {
  rec_t *r = ctx;
  if (r->n < REC_MAX) {
    r->v[r->n] = i;
    v3_copy(r->f[r->n], f);
  }
  r->n++;
}

static int load(const char *name, mesh_t *m) { return test_mesh_load(name, m) == 0; }

static void test_coarse_triangle(void) {
  mesh_t m;
  CHECK(load("tissue_block.obj", &m));
  if (!m.nverts) return;
  CHECK(m.nverts == 45);
  /* The triangle nearest the patch centre. */
  size_t ti = 0;
  double best = INFINITY, c[3] = {0};
  for (size_t i = 0; i < m.ntris; i++) {
    double g[3] = {0, 0, 0};
    for (int j = 0; j < 3; j++) v3_axpy(g, m.pos + 3 * m.tris[3 * i + j], 1.0 / 3);
    if (v3_norm(g) < best) best = v3_norm(g), ti = i, v3_copy(c, g);
  }
  const uint32_t *tv = m.tris + 3 * ti;
  double e1[3], e2[3], n[3];
  v3_sub(e1, m.pos + 3 * tv[1], m.pos + 3 * tv[0]);
  v3_sub(e2, m.pos + 3 * tv[2], m.pos + 3 * tv[0]);
  v3_cross(n, e1, e2);
  v3_normalize(n);
  /* A tool tilted 30 degrees off the normal, its tip 12 mm below the
   * patch, so the shaft (from 4.35 mm above the tip) rises through the
   * triangle's centroid. */
  double ax[3] = {0.5, 0, 0};
  v3_axpy(ax, n, sqrt(0.75));
  v3_normalize(ax);
  double tip[3], p0[3], p1[3];
  v3_copy(tip, c);
  v3_axpy(tip, ax, -0.012);
  const double r_tip = 0.003, radius = SHAFT_RADIUS_FRACTION * r_tip, k = 400;
  shaft_segment(tip, ax, r_tip, 0.1, p0, p1);

  aabb_tree_t tree;
  verr_t e;
  CHECK(aabb_tree_build(&tree, m.pos, m.nverts, m.tris, m.ntris, &e) == 0);

  /* The old cylinder node test alone: nothing. */
  static rec_t old, with_tree, scan;
  double f_old[3] = {0, 0, 0};
  size_t n_old = shaft_push(p0, p1, radius, k, m.pos, m.nverts, record, &old, f_old);
  double nearest = INFINITY;
  for (size_t i = 0; i < m.nverts; i++) {
    double d[3];
    v3_sub(d, m.pos + 3 * i, p0);
    v3_axpy(d, ax, -v3_dot(d, ax));
    nearest = fmin(nearest, v3_norm(d));
  }
  printf("coarse: triangle %zu, nearest vertex %.2f mm from the axis (shaft radius %.2f mm); node test pushes %zu\n",
         ti, nearest * 1e3, radius * 1e3, n_old);
  CHECK(n_old == 0 && old.n == 0 && v3_norm(f_old) == 0);

  shaft_surface_t s = {m.pos, m.nverts, m.tris, m.ntris, &tree, 0, NULL, 0};
  shaft_stats_t st;
  double ft[3] = {0, 0, 0}, fs[3] = {0, 0, 0};
  size_t nt = shaft_contact(p0, p1, radius, k, &s, record, &with_tree, ft, &st);
  s.tree = NULL;
  shaft_stats_t st2;
  size_t ns = shaft_contact(p0, p1, radius, k, &s, record, &scan, fs, &st2);
  printf("coarse: shaft contact pushes %zu vertices (%zu crossings), tool force (%.4f %.4f %.4f) N\n", nt, st.crossings,
         ft[0], ft[1], ft[2]);
  CHECK(nt == 3 && st.nodes == 0 && st.crossings == 1 && st.corners == 3 && with_tree.n == 3);
  /* Tree and scan: the same forces to the bit. */
  CHECK(ns == nt && scan.n == with_tree.n && memcmp(scan.v, with_tree.v, sizeof scan.v) == 0 &&
        memcmp(scan.f, with_tree.f, sizeof scan.f) == 0 && memcmp(ft, fs, sizeof ft) == 0);
  CHECK(st2.crossings == st.crossings && st2.corners == st.corners);

  /* The three corners, each perpendicular to the axis and into the tissue
   * (-n), shares by barycentric weight: the centroid gets a third each. */
  double sum[3] = {0, 0, 0};
  double fexp = fmin(k * radius, SHAFT_MAX_VERTEX_FORCE);
  for (size_t i = 0; i < with_tree.n && i < 3; i++) {
    const double *f = with_tree.f[i];
    CHECK(with_tree.v[i] == tv[0] || with_tree.v[i] == tv[1] || with_tree.v[i] == tv[2]);
    CHECK(isfinite(f[0]) && isfinite(f[1]) && isfinite(f[2]));
    CHECK(fabs(v3_dot(f, ax)) < 1e-12);
    CHECK(v3_dot(f, n) < 0);
    CHECK_NEAR(v3_norm(f), fexp / 3, 1e-9);
    v3_add(sum, sum, f);
  }
  CHECK(with_tree.v[0] != with_tree.v[1] && with_tree.v[1] != with_tree.v[2] && with_tree.v[0] != with_tree.v[2]);
  /* The tool gets the opposite: out of the tissue, off the axis. */
  CHECK_NEAR(ft[0], -sum[0], 1e-15);
  CHECK_NEAR(ft[1], -sum[1], 1e-15);
  CHECK_NEAR(ft[2], -sum[2], 1e-15);
  CHECK(v3_dot(ft, n) > 0 && fabs(v3_dot(ft, ax)) < 1e-12);
  CHECK_NEAR(v3_norm(ft), fexp, 1e-9);

  /* Crossing the triangle away from its centroid: the nearest corner takes
   * the largest share. */
  double toward[3], c2[3];
  v3_sub(toward, m.pos + 3 * tv[0], c);
  v3_copy(c2, c);
  v3_axpy(c2, toward, 0.5);
  v3_copy(tip, c2);
  v3_axpy(tip, ax, -0.012);
  shaft_segment(tip, ax, r_tip, 0.1, p0, p1);
  s.tree = &tree;
  static rec_t off;
  double fo[3] = {0, 0, 0};
  shaft_contact(p0, p1, radius, k, &s, record, &off, fo, &st);
  double share0 = 0, others = 0;
  for (size_t i = 0; i < off.n && i < REC_MAX; i++) {
    if (off.v[i] == tv[0])
      share0 = v3_norm(off.f[i]);
    else
      others = fmax(others, v3_norm(off.f[i]));
  }
  printf("coarse: crossing halfway to corner %u: its share %.4f N, the others' largest %.4f N (%zu node pushes)\n",
         tv[0], share0, others, st.nodes);
  CHECK(st.crossings == 1 && share0 > others);
  aabb_tree_destroy(&tree);
  mesh_free(&m);
}

/* Random segments: tree vs scan, forces to the bit, the per-vertex bound. */
static void sweep(const char *name, double wobble, int refit) {
  mesh_t m;
  CHECK(load(name, &m));
  if (!m.nverts) return;
  double lo[3], hi[3];
  mesh_bounds(&m, lo, hi);
  double diag = 0;
  for (int j = 0; j < 3; j++) diag = fmax(diag, hi[j] - lo[j]);
  uint64_t rng = 0x5eedu + m.nverts;
  aabb_tree_t tree;
  verr_t e;
  CHECK(aabb_tree_build(&tree, m.pos, m.nverts, m.tris, m.ntris, &e) == 0);
  double slack = 0;
  if (wobble > 0) {
    /* Deform in place as a model would; then either refit (the tree after
     * a step) or leave the boxes stale and pass the largest displacement
     * as slack (the tree inside a step). */
    for (size_t i = 0; i < 3 * m.nverts; i++) {
      double d = wobble * diag * sin(37.0 * m.pos[(i + 1) % (3 * m.nverts)] / diag);
      m.pos[i] += d;
      slack = fmax(slack, fabs(d) * sqrt(3.0));
    }
    if (refit) {
      aabb_tree_refit(&tree, m.pos);
      slack = 0;
    }
  }
  static rec_t a, b;
  size_t agree = 0, missed_without_slack = 0, total_cross = 0, max_cross = 0, bounded = 1, once = 1, runs = 300;
  for (size_t r = 0; r < runs; r++) {
    double p0[3], p1[3];
    for (int j = 0; j < 3; j++) {
      double mid = 0.5 * (lo[j] + hi[j]), span = hi[j] - lo[j];
      p0[j] = mid + span * (test_rng_uniform(&rng) - 0.5) * 1.2;
      p1[j] = mid + span * (test_rng_uniform(&rng) - 0.5) * 1.2;
    }
    shaft_surface_t s = {m.pos, m.nverts, m.tris, m.ntris, &tree, slack, NULL, 0};
    uint32_t t1[SHAFT_MAX_CROSSINGS], t2[SHAFT_MAX_CROSSINGS];
    double u1[SHAFT_MAX_CROSSINGS], u2[SHAFT_MAX_CROSSINGS], b1[SHAFT_MAX_CROSSINGS][3], b2[SHAFT_MAX_CROSSINGS][3];
    size_t n1 = shaft_crossings(p0, p1, &s, t1, u1, b1, SHAFT_MAX_CROSSINGS);
    s.tree = NULL;
    size_t n2 = shaft_crossings(p0, p1, &s, t2, u2, b2, SHAFT_MAX_CROSSINGS);
    int same = n1 == n2 && memcmp(t1, t2, n1 * sizeof *t1) == 0 && memcmp(u1, u2, n1 * sizeof *u1) == 0;
    if (slack > 0) {
      /* The same stale boxes without the slack: some crossings escape. */
      s.tree = &tree;
      s.slack = 0;
      missed_without_slack += shaft_crossings(p0, p1, &s, t1, u1, b1, SHAFT_MAX_CROSSINGS) < n2;
      s.slack = slack;
    }
    total_cross += n1;
    if (n1 > max_cross) max_cross = n1;
    /* Contact with a thick shaft (radius 2% of the organ) and a stiff spring. */
    double radius = 0.02 * diag, fa[3] = {0, 0, 0}, fb[3] = {0, 0, 0};
    a.n = b.n = 0;
    s.tree = &tree;
    shaft_contact(p0, p1, radius, 1e5, &s, record, &a, fa, NULL);
    s.tree = NULL;
    shaft_contact(p0, p1, radius, 1e5, &s, record, &b, fb, NULL);
    same = same && a.n == b.n && a.n <= REC_MAX && memcmp(a.v, b.v, a.n * sizeof *a.v) == 0 &&
           memcmp(a.f, b.f, a.n * sizeof *a.f) == 0 && memcmp(fa, fb, sizeof fa) == 0;
    agree += same;
    for (size_t i = 0; i < a.n && i < REC_MAX; i++) {
      bounded &= v3_norm(a.f[i]) <= SHAFT_MAX_VERTEX_FORCE * (1 + 1e-12);
      for (size_t j = 0; j < i; j++) once &= a.v[i] != a.v[j];
    }
  }
  printf("sweep %s%s: %zu segments, tree == scan in %zu, %zu crossings (max %zu per segment)\n", name,
         wobble > 0 ? (refit ? " (deformed, refit)" : " (deformed, stale boxes + slack)") : "", runs, agree,
         total_cross, max_cross);
  CHECK(agree == runs);
  if (slack > 0) {
    printf("  stale boxes without the slack (%.2f mm): %zu segments miss crossings\n", slack * 1e3,
           missed_without_slack);
    CHECK(missed_without_slack > 0);
  }
  CHECK(total_cross > runs / 2); /* the segments do meet the organ */
  CHECK(bounded && once);
  aabb_tree_destroy(&tree);
  mesh_free(&m);
}

int main(void) {
  if (!getenv("VISCERA_SOURCE_DIR")) {
    fprintf(stderr, "test_shaft: VISCERA_SOURCE_DIR not set (run through ctest)\n");
    return 77;
  }
  test_coarse_triangle();
  sweep("kidney.obj", 0, 0);
  sweep("kidney.obj", 0.01, 1);
  sweep("kidney.obj", 0.01, 0);
  sweep("liver_large.obj", 0, 0);
  return check_report("test_shaft");
}
