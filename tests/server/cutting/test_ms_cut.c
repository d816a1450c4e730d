/* SPDX-License-Identifier: Apache-2.0 */
/* Three-stage mass-spring cutting (docs/methods.md D): Bezier eq. 5-8 against hand
 * values; swept deletion against brute force; node matching (shortest
 * distance, shorter diagonals); straight cuts across and inside the tissue
 * block, a generated sheet and a closed organ leave a valid mesh (manifold,
 * oriented, no degenerate faces, no NaN; a cut across gives two pieces);
 * residual stress opens the wound, which then shrinks to a stable width,
 * and does not without it (eps_r = 0); allocation only when cutting. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "cutting/bezier.h"
#include "cutting/ms_cut.h"
#include "cutting/ms_cut_sweep.h"
#include "cutting/node_match.h"
#include "ms_cut_fixture.h"
#include "physics/integrator.h"
#include "physics/mass_spring.h"
#include "physics/model_mass_spring.h"
#include "test_rng.h"

static uint64_t rng_state = 0x2545f4914f6cdd1dull;
static double urand(void) { return test_rng_uniform(&rng_state); }

static void test_bezier(void) {
  const double P[4][3] = {{0, 0, 0}, {1, 2, 0}, {3, 2, 1}, {4, 0, 0}};
  double q[3], qm[3];
  /* a = 1/2: weights 1/8, 3/8, 3/8, 1/8. */
  bezier_eval(P, 0.5, q);
  CHECK_NEAR(q[0], 2.0, 1e-15);
  CHECK_NEAR(q[1], 1.5, 1e-15);
  CHECK_NEAR(q[2], 0.375, 1e-15);
  /* a = 1/3: weights 8/27, 12/27, 6/27, 1/27. */
  bezier_eval(P, 1.0 / 3, q);
  CHECK_NEAR(q[0], 34.0 / 27, 1e-15);
  CHECK_NEAR(q[1], 36.0 / 27, 1e-15);
  CHECK_NEAR(q[2], 6.0 / 27, 1e-15);
  /* End points (the curve passes through P0 and P3). */
  bezier_eval(P, 0, q);
  CHECK(q[0] == 0 && q[1] == 0 && q[2] == 0);
  bezier_eval(P, 1, q);
  CHECK(q[0] == 4 && q[1] == 0 && q[2] == 0);
  /* Eq. 6 and 7. */
  CHECK_NEAR(bezier_bernstein(1, 3, 0.25), 3 * 0.25 * 0.75 * 0.75, 1e-16);
  CHECK_NEAR(bezier_bernstein(2, 5, 0.5), 10.0 / 32, 1e-16);
  CHECK_NEAR(bezier_bernstein(0, 3, 0.2), 0.512, 1e-15);
  CHECK(bezier_bernstein(4, 3, 0.5) == 0);
  double sum = 0;
  for (int k = 0; k <= 7; k++) sum += bezier_bernstein(k, 7, 0.3);
  CHECK_NEAR(sum, 1, 1e-14);
  /* B_1,3 peaks at a = 1/3 and B_2,3 at a = 2/3 (the seed's remark). */
  CHECK(bezier_bernstein(1, 3, 1.0 / 3) > bezier_bernstein(1, 3, 1.0 / 3 + 1e-3));
  CHECK(bezier_bernstein(1, 3, 1.0 / 3) > bezier_bernstein(1, 3, 1.0 / 3 - 1e-3));
  CHECK(bezier_bernstein(2, 3, 2.0 / 3) > bezier_bernstein(2, 3, 2.0 / 3 + 1e-3));
  /* Eq. 8 (matrix form) equals eq. 5 everywhere; the tangent matches differences. */
  double worst = 0, worst_t = 0;
  for (int i = 0; i <= 100; i++) {
    double a = i / 100.0, t[3], p1[3], p2[3];
    bezier_eval(P, a, q);
    bezier_eval_matrix(P, a, qm);
    worst = fmax(worst, v3_dist(q, qm));
    bezier_tangent(P, a, t);
    bezier_eval(P, a + 1e-6, p1);
    bezier_eval(P, a - 1e-6, p2);
    for (int d = 0; d < 3; d++) worst_t = fmax(worst_t, fabs(t[d] - (p1[d] - p2[d]) / 2e-6));
  }
  CHECK(worst < 1e-14);
  CHECK(worst_t < 1e-6);
  /* Fit through a bent path: the curve passes through its ends and through
   * the path points at 1/3 and 2/3 of its length at a = 1/3, 2/3. */
  const double path[4 * 3] = {0, 0, 0, 3, 0, 0, 3, 3, 0, 6, 3, 0}; /* length 9 */
  double C[4][3], w[4], Cr[4][3];
  double len = bezier_fit_path(path, 4, NULL, w, C);
  CHECK_NEAR(len, 9, 1e-15);
  bezier_eval(C, 1.0 / 3, q);
  CHECK_NEAR(v3_dist(q, (double[]){3, 0, 0}), 0, 1e-14);
  bezier_eval(C, 2.0 / 3, q);
  CHECK_NEAR(v3_dist(q, (double[]){3, 3, 0}), 0, 1e-14);
  /* The same weights on a shifted copy give the shifted curve. */
  double moved[12];
  for (int k = 0; k < 12; k++) moved[k] = path[k] + (k % 3 == 2 ? 1 : 0);
  bezier_fit_path(moved, 4, w, NULL, Cr);
  for (int k = 0; k < 4; k++) CHECK_NEAR(Cr[k][2] - C[k][2], 1, 1e-14);
  /* Nearest point. */
  double d;
  double a = bezier_nearest(C, (double[]){3, 0, 0}, 64, &d);
  CHECK_NEAR(a, 1.0 / 3, 2e-3);
  CHECK(d < 1e-3);
  printf("bezier: eq. 5 = eq. 8 within %.1e, tangent within %.1e, fit through path points\n", worst, worst_t);
}

/* Stage 1 against brute force: distances from dense samples of the path
 * (and of each spring) instead of closest points. Sampling can only
 * overestimate a distance, by at most half the sample spacing, so the two
 * must agree for every node and spring not within that band of r. */
static void test_sweep_brute_force(void) {
  mesh_t m;
  if (fx_sheet(&m, 31, 19, 0.1, 0.06)) {
    CHECK(0);
    return;
  }
  for (size_t i = 0; i < m.nverts; i++) /* jitter, out of plane too */
    for (int k = 0; k < 3; k++) m.pos[3 * i + k] += (urand() - 0.5) * (k == 2 ? 0.002 : 0.0015);
  int bad_nodes = 0, bad_springs = 0, bad_tris = 0, band = 0, in_nodes = 0, in_springs = 0;
  for (int trial = 0; trial < 6; trial++) {
    double path[5 * 3];
    size_t np = 1 + (size_t)trial % 5;
    for (size_t i = 0; i < np; i++) {
      path[3 * i] = -0.04 + 0.08 * urand();
      path[3 * i + 1] = -0.025 + 0.05 * urand();
      path[3 * i + 2] = (urand() - 0.5) * 0.004;
    }
    double r = 0.002 + 0.004 * urand();
    uint8_t *node_in = malloc(m.nverts), *tri_dead = malloc(m.ntris);
    ms_sweep_mark(m.nverts, m.pos, m.ntris, m.tris, path, np, r, NULL, 0, node_in, tri_dead);
    /* Brute force. */
    const int S = 200;
    double spacing = 0;
    for (size_t i = 0; i + 1 < np; i++) spacing = fmax(spacing, v3_dist(path + 3 * i, path + 3 * i + 3) / S);
    double samples[4 * 201 * 3 + 3];
    size_t ns = 0;
    for (size_t i = 0; i + 1 < np; i++)
      for (int s = 0; s <= S; s++)
        for (int k = 0; k < 3; k++)
          samples[3 * ns + k] = path[3 * i + k] + (path[3 * i + 3 + k] - path[3 * i + k]) * s / S, ns += (k == 2);
    if (np == 1) {
      v3_copy(samples, path);
      ns = 1;
    }
    uint8_t *bf_node = malloc(m.nverts);
    double plo[3] = {INFINITY, INFINITY, INFINITY}, phi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < np; i++)
      for (int k = 0; k < 3; k++) {
        plo[k] = fmin(plo[k], path[3 * i + k]);
        phi[k] = fmax(phi[k], path[3 * i + k]);
      }
    for (size_t v = 0; v < m.nverts; v++) {
      double d = INFINITY;
      for (size_t s = 0; s < ns; s++) d = fmin(d, v3_dist(m.pos + 3 * v, samples + 3 * s));
      bf_node[v] = d < r;
      in_nodes += bf_node[v];
      if (fabs(d - r) <= spacing) {
        band++;
        continue;
      }
      bad_nodes += bf_node[v] != node_in[v];
    }
    for (size_t t = 0; t < m.ntris; t++) {
      int bf_dead = 0, ambiguous = 0;
      for (int e = 0; e < 3; e++) {
        const double *a = m.pos + 3 * (size_t)m.tris[3 * t + e], *b = m.pos + 3 * (size_t)m.tris[3 * t + (e + 1) % 3];
        /* Separated boxes: farther than r for sure (no sampling needed). */
        int far = 0;
        for (int k = 0; k < 3; k++) far |= fmin(a[k], b[k]) > phi[k] + r || fmax(a[k], b[k]) < plo[k] - r;
        if (far) {
          bad_springs += ms_sweep_seg_path_dist(a, b, path, np) < r;
          continue;
        }
        double d = INFINITY, elen = v3_dist(a, b);
        const int E = 60;
        for (int q = 0; q <= E; q++) {
          double p[3];
          for (int k = 0; k < 3; k++) p[k] = a[k] + (b[k] - a[k]) * q / E;
          for (size_t s = 0; s < ns; s++) d = fmin(d, v3_dist(p, samples + 3 * s));
        }
        double tol = spacing + elen / E;
        double exact = ms_sweep_seg_path_dist(a, b, path, np);
        if (fabs(d - r) <= tol) {
          ambiguous = 1;
          continue;
        }
        in_springs += d < r;
        bad_springs += (d < r) != (exact < r);
        bf_dead |= d < r;
      }
      for (int e = 0; e < 3; e++) bf_dead |= bf_node[m.tris[3 * t + e]];
      if (!ambiguous) bad_tris += bf_dead != tri_dead[t];
    }
    free(node_in);
    free(tri_dead);
    free(bf_node);
  }
  CHECK(bad_nodes == 0);
  CHECK(bad_springs == 0);
  CHECK(bad_tris == 0);
  CHECK(in_nodes > 20 && in_springs > 40); /* the trials did delete something */
  printf("sweep: %d nodes and %d springs inside over 6 paths, brute force agrees (%d borderline skipped); "
         "mismatches nodes %d springs %d triangles %d\n",
         in_nodes, in_springs, band, bad_nodes, bad_springs, bad_tris);
  mesh_free(&m);
}

/* Stage 3 on a straight interior cut of a sheet, checked on its outputs:
 * every hole-boundary node is connected to the curve node at its nearest
 * point (within the merge tolerance), the connection is an edge of the new
 * triangles, and every quadrilateral between two neighbours and their two
 * curve nodes is split by its shorter diagonal. */
static void test_node_matching(void) {
  mesh_t m;
  if (fx_sheet(&m, 41, 25, 0.1, 0.06)) {
    CHECK(0);
    return;
  }
  for (size_t i = 0; i < m.nverts; i++) /* irregular, so diagonals differ */
    for (int k = 0; k < 2; k++) m.pos[3 * i + k] += (urand() - 0.5) * 0.0012;
  double path[21 * 3];
  for (int i = 0; i <= 20; i++) {
    path[3 * i] = -0.02 + 0.04 * i / 20;
    path[3 * i + 1] = 0.0013 + 0.004 * sin(i / 20.0 * 3.14159); /* gently bent */
    path[3 * i + 2] = 0;
  }
  const double r = 0.002, h = 0.0025, merge_tol = 0.5 * h;
  uint8_t *node_in = malloc(m.nverts), *tri_dead = malloc(m.ntris);
  ms_sweep_mark(m.nverts, m.pos, m.ntris, m.tris, path, 21, r, NULL, 0, node_in, tri_dead);
  ms_sweep_out_t sw;
  verr_t err;
  CHECK(ms_sweep_cleanup(m.nverts, m.ntris, m.tris, tri_dead, &sw, &err) == 0);
  double C[4][3], w[4];
  bezier_fit_path(path, 21, NULL, w, C);
  nm_result_t nm;
  CHECK(node_match(m.nverts, m.pos, sw.nhole, sw.hole, C, merge_tol, &nm, &err) == 0);
  const size_t n = m.nverts;
  uint32_t *match = malloc(n * sizeof *match);
  for (size_t i = 0; i < n; i++) match[i] = UINT32_MAX;
  for (size_t k = 0; k < nm.nmatch; k++) match[nm.match_node[k]] = nm.match_to[k];
  int unmatched = 0, not_nearest = 0, missing_edge = 0, ends = 0;
  double worst_excess = 0;
  for (size_t e = 0; e < 2 * sw.nhole; e++) {
    uint32_t b = sw.hole[e];
    if (match[b] == UINT32_MAX) {
      unmatched++;
      continue;
    }
    double q[3], dmin;
    bezier_nearest(C, m.pos + 3 * (size_t)b, 512, &dmin);
    bezier_eval(C, nm.a[match[b] - n], q);
    double excess = v3_dist(q, m.pos + 3 * (size_t)b) - dmin;
    double a_to = nm.a[match[b] - n];
    if (a_to == 0 || a_to == 1) {
      ends++; /* yellow: connected to an end of the curve */
      double a_near = bezier_nearest(C, m.pos + 3 * (size_t)b, 512, NULL);
      double arc = bezier_length(C, fmin(a_near, a_to), fmax(a_near, a_to), 64);
      /* Its nearest point is that end, or it is the split node beside it. */
      not_nearest += arc > merge_tol + 3 * h;
    } else {
      worst_excess = fmax(worst_excess, excess);
      not_nearest += excess > merge_tol;
    }
    int found = 0;
    for (size_t t = 0; t < nm.ntris && !found; t++) {
      const uint32_t *f = nm.tris + 3 * t;
      int hb = f[0] == b || f[1] == b || f[2] == b, hc = f[0] == match[b] || f[1] == match[b] || f[2] == match[b];
      found = hb && hc;
    }
    missing_edge += !found;
  }
  /* Quadrilaterals: two new triangles sharing an edge (chain node, curve
   * node) whose other two corners are the other chain node and curve node,
   * each chain node matched to one of the two curve nodes. */
  int quads = 0, longer = 0;
  for (size_t t1 = 0; t1 < nm.ntris; t1++)
    for (size_t t2 = t1 + 1; t2 < nm.ntris; t2++) {
      const uint32_t *f = nm.tris + 3 * t1, *g = nm.tris + 3 * t2;
      uint32_t shared[3];
      int ns = 0;
      for (int x = 0; x < 3; x++)
        for (int y = 0; y < 3; y++)
          if (f[x] == g[y]) shared[ns++] = f[x];
      if (ns != 2 || (shared[0] < n) == (shared[1] < n)) continue;
      uint32_t of = 0, og = 0;
      for (int x = 0; x < 3; x++) {
        if (f[x] != shared[0] && f[x] != shared[1]) of = f[x];
        if (g[x] != shared[0] && g[x] != shared[1]) og = g[x];
      }
      if ((of < n) == (og < n)) continue;
      uint32_t u = shared[0] < n ? shared[0] : shared[1], c = shared[0] < n ? shared[1] : shared[0];
      uint32_t w2 = of < n ? of : og, c2 = of < n ? og : of;
      int mu = match[u] == c || match[u] == c2, mw = match[w2] == c || match[w2] == c2;
      if (!mu || !mw || match[u] == match[w2]) continue;
      double pc[3], pc2[3];
      bezier_eval(C, nm.a[c - n], pc);
      bezier_eval(C, nm.a[c2 - n], pc2);
      quads++;
      longer += v3_dist(m.pos + 3 * (size_t)u, pc) > v3_dist(m.pos + 3 * (size_t)w2, pc2) + 1e-12;
    }
  CHECK(sw.nhole > 20);
  CHECK(unmatched == 0);
  CHECK(not_nearest == 0);
  CHECK(missing_edge == 0);
  CHECK(ends >= 2);
  CHECK(quads > 10 && longer == 0);
  CHECK(nm.nlips == 2 && nm.lips[0].side != nm.lips[1].side && nm.open_left == 0);
  printf("node matching: %zu hole edges, %zu curve nodes, %zu triangles; every boundary node connected to its "
         "nearest curve node (worst excess %.2g mm, tolerance %.2g mm), %d to the ends; %d quadrilaterals, all by "
         "the shorter diagonal\n",
         sw.nhole, nm.nnew, nm.ntris, worst_excess * 1e3, merge_tol * 1e3, ends, quads);
  nm_result_free(&nm);
  ms_sweep_out_free(&sw);
  free(node_in);
  free(tri_dead);
  free(match);
  mesh_free(&m);
}

/* A straight cut on a model; checks the mesh and reports. */
static int cut_model(const char *what, const mesh_t *mesh, double ax, double ay, double bx, double by, double z0,
                     double radius, size_t want_components, model_t **out_model, ms_cut_t **out_cut) {
  verr_t err;
  model_t *m = fx_model(mesh, FX_DEFAULT_MATERIAL, "symplectic_euler", 1e-3, &err);
  if (!m) {
    printf("%s: %s\n", what, err.msg);
    CHECK(0);
    return -1;
  }
  ms_cut_t *c = ms_cut_create(m, NULL, &err);
  CHECK(c != NULL);
  if (!c) return -1;
  int changes = 0;
  uint32_t v0 = m->topology_version;
  long steps = fx_stroke(m, c, (double[]){ax, ay}, (double[]){bx, by}, z0, radius, 0.1, 1e-3, NULL, &changes);
  CHECK(steps > 0);
  CHECK(changes > 0 && m->topology_version == v0 + (uint32_t)changes);
  for (int s = 0; s < 500; s++) m->ops->step(m, 1e-3);
  fx_check_t ck;
  CHECK(fx_check(m, &ck) == 0);
  fx_print(what, &ck);
  CHECK(fx_valid(&ck));
  CHECK(ck.r.components == want_components);
  CHECK(m->rollbacks == 0);
  /* Sub-steps follow the stability bound of the cut mesh. */
  CHECK(m->substeps >= 1 && 1e-3 / m->substeps <= 0.9 * m->stable_dt * (1 + 1e-12));
  /* The warm-started re-estimate agrees with a cold power iteration on the cut mesh. */
  double lk, lc;
  const mass_spring_t *sys = model_mass_spring_surface_system(m);
  CHECK(mass_spring_eigen_bounds(sys, 0, &lk, &lc) == 0);
  /* Symplectic Euler caps the dampers' rate (damping_scale, mass_spring.h). */
  double cold = integrator_stable_dt(INT_SYMPLECTIC_EULER, lk, lc * sys->damping_scale);
  CHECK(fabs(m->stable_dt / cold - 1) < 0.01);
  const ms_cut_stats_t *st = ms_cut_stats(c);
  CHECK(st->cuts == 1 && st->holes_left_open == 0);
  printf("  %ld steps, %llu segments, nodes -%llu +%llu, triangles -%llu +%llu, springs cut %llu, sub-steps %d (stable "
         "dt %.3g ms, cold estimate %.3g ms), last segment %.2f ms\n",
         steps, (unsigned long long)st->segments, (unsigned long long)st->nodes_deleted,
         (unsigned long long)st->nodes_added, (unsigned long long)st->tris_deleted, (unsigned long long)st->tris_added,
         (unsigned long long)st->springs_cut, m->substeps, m->stable_dt * 1e3, cold * 1e3, st->last_segment_ms);
  *out_model = m;
  *out_cut = c;
  return 0;
}

static void test_cuts(void) {
  mesh_t block, sheet, spleen;
  model_t *m;
  ms_cut_t *c;
  if (test_mesh_load("tissue_block.obj", &block) || fx_sheet(&sheet, 61, 37, 0.1, 0.06) ||
      test_mesh_load("spleen.obj", &spleen)) {
    CHECK(0);
    return;
  }
  /* Across the tissue block (10 x 6 cm): two pieces. */
  if (cut_model("tissue block, cut across", &block, -0.07, 0.0031, 0.07, 0.0031, 0, 0.001, 2, &m, &c) == 0) {
    ms_cut_destroy(c);
    model_destroy(m);
  }
  /* Across the sheet, slanted: two pieces; inside it: one piece, a wound. */
  if (cut_model("sheet, cut across", &sheet, -0.07, -0.012, 0.07, 0.013, 0, 0.001, 2, &m, &c) == 0) {
    ms_cut_destroy(c);
    model_destroy(m);
  }
  if (cut_model("sheet, cut inside", &sheet, -0.03, 0.0011, 0.03, 0.0011, 0, 0.001, 1, &m, &c) == 0) {
    double mean, max;
    size_t nw = ms_cut_incision_width(c, &mean, &max);
    printf("  width: %zu lip nodes, mean %.3g mm, max %.3g mm, %zu lips\n", nw, mean * 1e3, max * 1e3,
           ms_cut_lip_count(c));
    CHECK(nw > 5);
    CHECK(ms_cut_lip_count(c) >= 2);
    ms_cut_destroy(c);
    model_destroy(m);
  }
  /* A closed organ: the wound is the only boundary. */
  double lo[3], hi[3];
  mesh_bounds(&spleen, lo, hi);
  double cx = 0.5 * (lo[0] + hi[0]), cy = 0.5 * (lo[1] + hi[1]), L = 0.3 * (hi[0] - lo[0]);
  if (cut_model("spleen, cut on top", &spleen, cx - L, cy + 1e-4, cx + L, cy + 1e-4, hi[2], 0.001, 1, &m, &c) == 0) {
    fx_check_t ck;
    fx_check(m, &ck);
    CHECK(ck.r.boundary_edges > 0);
    ms_cut_destroy(c);
    model_destroy(m);
  }
  mesh_free(&block);
  mesh_free(&sheet);
  mesh_free(&spleen);
}

/* Width of an interior cut over time after the stroke: n samples, one per
 * `every` steps, into w[]. The whole cut is one segment, applied when the
 * stroke ends (segment_length 1 m), so t = 0 is the moment the springs are
 * cut: the seed's Fig. 6 set-up. Returns 0 or -1. */
static int width_curve(const mesh_t *mesh, fx_material_t mat, double eps_r, int n, int every, double *w) {
  verr_t err;
  model_t *m = fx_model(mesh, mat, "symplectic_euler", 1e-3, &err);
  if (!m) {
    printf("%s\n", err.msg);
    return -1;
  }
  ms_cut_params_t p = ms_cut_default_params();
  p.eps_r = eps_r;
  p.segment_length = 1.0;
  ms_cut_t *c = ms_cut_create(m, &p, &err);
  int rc = -1;
  if (c && fx_stroke(m, c, (double[]){-0.03, 0.0011}, (double[]){0.03, 0.0011}, 0, 0.001, 0.5, 1e-3, NULL, NULL) > 0) {
    rc = 0;
    for (int i = 0; i < n; i++) {
      for (int s = 0; s < every; s++) m->ops->step(m, 1e-3);
      if (ms_cut_incision_width(c, &w[i], NULL) == 0) rc = -1;
    }
  }
  ms_cut_destroy(c);
  model_destroy(m);
  return rc;
}

/* The seed's Fig. 6 shape: opens fast (peak early), shrinks (the end is at
 * least 5 % below the peak) and is stable (the last 100 ms vary by less
 * than 1 % of the final width). */
static int fig6_shape(const double *w, int n, int dt_ms, double *peak, int *peak_ms, double *final, double *spread) {
  int ip = 0;
  for (int i = 0; i < n; i++)
    if (w[i] > w[ip]) ip = i;
  int tail = 100 / dt_ms;
  double lo = INFINITY, hi = -INFINITY, sum = 0;
  for (int i = n - tail; i < n; i++) {
    lo = fmin(lo, w[i]);
    hi = fmax(hi, w[i]);
    sum += w[i];
  }
  *peak = w[ip];
  *peak_ms = (ip + 1) * dt_ms;
  *final = sum / tail;
  *spread = hi - lo;
  return *peak > 1e-5 && *peak_ms <= 100 && *final <= 0.95 * *peak && *final > 0 && *spread <= 0.01 * *final;
}

static void test_residual_stress(void) {
  mesh_t sheet;
  if (fx_sheet(&sheet, 41, 25, 0.1, 0.06)) {
    CHECK(0);
    return;
  }
  enum { N = 300, DT = 2 }; /* 600 ms */
  double w[N], w0[N];
  /* Scene-default stiffness, heavier and lightly damped so the opening
   * takes tens of milliseconds and overshoots visibly. */
  const fx_material_t mat = {1.0, 30, 0.01, 30, 0.02};
  CHECK(width_curve(&sheet, mat, 0.1, N, DT, w) == 0);
  CHECK(width_curve(&sheet, mat, 0.0, N, DT, w0) == 0);
  double peak, final, spread, peak0, final0, spread0;
  int tp, tp0;
  int shape = fig6_shape(w, N, DT, &peak, &tp, &final, &spread);
  int shape0 = fig6_shape(w0, N, DT, &peak0, &tp0, &final0, &spread0);
  CHECK(shape);
  CHECK(w[0] > 0); /* it opens at once */
  CHECK(!shape0);
  CHECK(peak0 < 1e-3 * peak); /* without residual stress the wound does not open */
  printf("residual stress eps_r 0.1: width peak %.4f mm at %d ms, final %.4f mm (%.1f %% below the peak), last "
         "100 ms within %.2g %%; eps_r 0: peak %.2g mm, Fig. 6 shape %s\n",
         peak * 1e3, tp, final * 1e3, 100 * (1 - final / peak), 100 * spread / final, peak0 * 1e3,
         shape0 ? "yes" : "no");
  mesh_free(&sheet);
}

/* Allocation only when cutting; bad input refused; other models refused. */
static void test_allocation_and_input(void) {
  mesh_t sheet;
  if (fx_sheet(&sheet, 21, 13, 0.1, 0.06)) {
    CHECK(0);
    return;
  }
  verr_t err;
  model_t *m = fx_model(&sheet, FX_DEFAULT_MATERIAL, "symplectic_euler", 1e-3, &err);
  mass_spring_t *ms = model_mass_spring_surface_system(m);
  CHECK(ms && ms->f_res == NULL); /* a model nobody cuts has no cutting arrays */
  ms_cut_t *c = ms_cut_create(m, NULL, &err);
  CHECK(c != NULL);
  size_t b0 = ms_cut_bytes(c);
  /* Far from the tissue: nothing more is allocated, nothing changes. */
  double far0[3] = {0.5, 0.5, 0.5}, far1[3] = {0.5, 0.5, 0.4};
  CHECK(ms_cut_step(c, far0, far1, 0.001, &err) == 0);
  CHECK(ms_cut_bytes(c) == b0 && ms->f_res == NULL && !ms_cut_active(c));
  /* Bad input: refused, counted nowhere, the model unchanged. */
  uint32_t v = m->topology_version;
  double nan3[3] = {NAN, 0, 0}, ok[3] = {0, 0, 0.01};
  CHECK(ms_cut_step(c, nan3, ok, 0.001, &err) == -1 && strstr(err.msg, "finite"));
  CHECK(ms_cut_step(c, ok, ok, 0, &err) == -1 && strstr(err.msg, "radius"));
  CHECK(ms_cut_step(c, ok, ok, 1.0, &err) == -1 && strstr(err.msg, "radius"));
  CHECK(ms_cut_step(c, ok, ok, INFINITY, &err) == -1);
  CHECK(m->topology_version == v);
  /* A cut allocates the residual forces and the path. */
  CHECK(fx_stroke(m, c, (double[]){-0.03, 0.0011}, (double[]){0.03, 0.0011}, 0, 0.001, 0.5, 1e-3, NULL, NULL) > 0);
  CHECK(ms->f_res != NULL && ms_cut_bytes(c) > b0 && m->topology_version > v);
  ms_cut_destroy(c);
  model_destroy(m);
  /* Other models cannot be cut by this method. */
  static scene_organ_t cfg;
  memset(&cfg, 0, sizeof cfg);
  snprintf(cfg.model, sizeof cfg.model, "mass_spring_tet");
  snprintf(cfg.integrator, sizeof cfg.integrator, "symplectic_euler");
  cfg.material =
      (scene_material_t){.mass = 0.1, .stiffness = 30, .damping = 0.02, .home_stiffness = 30, .home_damping = 0.005};
  mesh_t spleen;
  if (test_mesh_load("spleen.obj", &spleen) == 0) {
    model_params_t p = {.cfg = &cfg, .surface = &spleen, .dt = 1e-3};
    model_t *t = model_create(&p, &err);
    CHECK(t != NULL);
    if (t) {
      CHECK(ms_cut_create(t, NULL, &err) == NULL && strstr(err.msg, "mass_spring_surface"));
      model_destroy(t);
    }
    mesh_free(&spleen);
  }
  mesh_free(&sheet);
}

int main(void) {
  test_bezier();
  test_sweep_brute_force();
  test_node_matching();
  test_cuts();
  test_residual_stress();
  test_allocation_and_input();
  return check_report("test_ms_cut");
}
