/* SPDX-License-Identifier: Apache-2.0 */
/* aabb_tree_refit over what moved (fattened leaf boxes, dirty paths only),
 * on the gallbladder surface:
 * - at rest, and after every vertex crept by less than the margin, a refit
 *   recomputes no box (the counters refit_leaves, refit_nodes are 0);
 * - a few vertices pushed out by many margins: the refit recomputes only
 *   their leaves and paths (a small fraction of the nodes), the segment and
 *   nearest queries at the bump find the contact there exactly as a scan of
 *   every triangle does, while the same query on the stale boxes misses it
 *   (so the check can fail);
 * - random small motions for 200 refits (some vertices across the margin,
 *   most below): every leaf box still holds its triangles' current corners
 *   and random queries near the moved vertices match the scan;
 * - the whole organ shifted: every box recomputed (the plain sweep), and
 *   with margin 0 any motion recomputes its leaves;
 * - aabb_tree_refit_listed, given the moved vertices (shuffled, with
 *   unmoved ones and an index past the end among them), leaves every box,
 *   reference position and counter as the full refit does, over 100 rounds
 *   of jumps and creeps; a list missing a jumper leaves its box stale.
 * Skips (77) without the assets. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_rng.h"
#include "test_assets.h"
#include "collision/aabb_tree.h"
#include "mesh.h"
#include "vmath.h"

static uint64_t rng_state = 0x243f6a8885a308d3ull;
static double urand(void) { return test_rng_uniform(&rng_state); }

static int scan_segment(const double *x, const uint32_t *tris, size_t ntris, const double p0[3], const double p1[3],
                        aabb_hit_t *out) {
  double best = INFINITY, dir[3];
  v3_sub(dir, p1, p0);
  for (size_t t = 0; t < ntris; t++) {
    const double *a = x + 3 * tris[3 * t], *b = x + 3 * tris[3 * t + 1], *c = x + 3 * tris[3 * t + 2];
    double tt, bary[3], e1[3], e2[3], n[3];
    if (!seg_tri_intersect(p0, p1, a, b, c, &tt, bary) || tt >= best) continue;
    v3_sub(e1, b, a);
    v3_sub(e2, c, a);
    v3_cross(n, e1, e2);
    if (v3_dot(dir, n) >= 0) continue;
    best = tt;
    out->tri = (uint32_t)t;
    out->t = tt;
  }
  return isfinite(best);
}

static double scan_nearest(const double *x, const uint32_t *tris, size_t ntris, const double q[3], uint32_t *tri) {
  double best = INFINITY;
  for (size_t t = 0; t < ntris; t++) {
    double cp[3], bary[3], d[3];
    tri_closest_point(q, x + 3 * tris[3 * t], x + 3 * tris[3 * t + 1], x + 3 * tris[3 * t + 2], cp, bary);
    v3_sub(d, cp, q);
    double d2 = v3_dot(d, d);
    if (d2 < best) {
      best = d2;
      *tri = (uint32_t)t;
    }
  }
  return best;
}

/* Every leaf's box (in its parent's slot) holds the current corners. */
static size_t uncovered(const aabb_tree_t *t, const double *x) {
  size_t bad = 0;
  for (size_t l = 0; l < t->nleaves; l++) {
    uint32_t p = t->leaf_parent[l];
    const aabb_node_t *n = &t->nodes[p >> 1];
    for (uint32_t i = t->leaf_voff[l]; i < t->leaf_voff[l + 1]; i++)
      for (int k = 0; k < 3; k++) {
        double v = x[3 * t->leaf_vidx[i] + (uint32_t)k];
        bad += v < n->lo[k][p & 1] || v > n->hi[k][p & 1];
      }
  }
  return bad;
}

/* Outward normal at vertex v: the sum of its triangles' area normals. */
static void vertex_normal(const double *x, const uint32_t *tris, size_t ntris, uint32_t v, double n[3]) {
  n[0] = n[1] = n[2] = 0;
  for (size_t t = 0; t < ntris; t++) {
    const uint32_t *tv = tris + 3 * t;
    if (tv[0] != v && tv[1] != v && tv[2] != v) continue;
    double e1[3], e2[3], c[3];
    v3_sub(e1, x + 3 * tv[1], x + 3 * tv[0]);
    v3_sub(e2, x + 3 * tv[2], x + 3 * tv[0]);
    v3_cross(c, e1, e2);
    v3_add(n, n, c);
  }
  v3_scale(n, n, 1.0 / v3_norm(n));
}

int main(void) {
  mesh_t m;
  if (test_organ_load("gallbladder", &m)) return 77;
  verr_t err;
  aabb_tree_t t;
  CHECK(aabb_tree_build(&t, m.pos, m.nverts, m.tris, m.ntris, &err) == 0);
  double mg = t.margin;
  printf("gallbladder: %zu vertices, %zu leaves, %zu nodes, margin %.3g m\n", m.nverts, t.nleaves, t.nnodes, mg);
  CHECK(mg > 0);
  CHECK(t.refit_leaves == t.nleaves); /* the build's refit covers everything */
  double *x = malloc(3 * m.nverts * sizeof *x);
  memcpy(x, m.pos, 3 * m.nverts * sizeof *x);

  /* At rest, then a creep below the margin: nothing recomputed. */
  aabb_tree_refit(&t, x);
  CHECK(t.refit_leaves == 0 && t.refit_nodes == 0);
  for (size_t i = 0; i < 3 * m.nverts; i++) x[i] += (urand() - 0.5) * 1.6 * mg;
  aabb_tree_refit(&t, x);
  printf("rest and creep: %zu leaves, %zu nodes recomputed\n", t.refit_leaves, t.refit_nodes);
  CHECK(t.refit_leaves == 0 && t.refit_nodes == 0);
  CHECK(uncovered(&t, x) == 0);

  /* A bump: vertex v and its neighbours pushed out by 30 margins. */
  uint32_t v = m.tris[3 * (m.ntris / 3)];
  double nrm[3], lift = 30 * mg;
  vertex_normal(x, m.tris, m.ntris, v, nrm);
  unsigned char *moved = calloc(m.nverts, 1);
  moved[v] = 1;
  for (size_t tr = 0; tr < m.ntris; tr++)
    if (m.tris[3 * tr] == v || m.tris[3 * tr + 1] == v || m.tris[3 * tr + 2] == v)
      for (int k = 0; k < 3; k++) moved[m.tris[3 * tr + (size_t)k]] = 1;
  size_t nmoved = 0, leaves_bound = 0;
  for (size_t i = 0; i < m.nverts; i++)
    if (moved[i]) {
      double s = i == v ? 1.0 : 0.5;
      for (int k = 0; k < 3; k++) x[3 * i + (size_t)k] += s * lift * nrm[k];
      nmoved++;
      leaves_bound += t.vleaf_off[i + 1] - t.vleaf_off[i];
    }
  /* A probe coming down the normal onto the bump's top, stopping above
   * where the surface was: only the bump can be hit. */
  double p0[3], p1[3];
  for (int k = 0; k < 3; k++) {
    p0[k] = x[3 * v + (size_t)k] + 0.5 * lift * nrm[k];
    p1[k] = x[3 * v + (size_t)k] - 0.5 * lift * nrm[k];
  }
  aabb_hit_t want = {0}, got = {0};
  CHECK(scan_segment(x, m.tris, m.ntris, p0, p1, &want));
  int stale = aabb_tree_segment_first(&t, p0, p1, AABB_SEG_ENTERING, INFINITY, &got);
  printf("bump: %zu vertices moved %.3g m; stale boxes %s the contact\n", nmoved, lift, stale ? "find" : "miss");
  CHECK(!stale); /* the boxes before the refit do not cover the bump */
  aabb_tree_refit(&t, x);
  printf("bump refit: %zu leaves (bound %zu), %zu of %zu nodes recomputed\n", t.refit_leaves, leaves_bound,
         t.refit_nodes, t.nnodes);
  CHECK(t.refit_leaves > 0 && t.refit_leaves <= leaves_bound);
  CHECK(t.refit_nodes > 0 && t.refit_nodes <= t.refit_leaves * (size_t)t.depth);
  CHECK(t.refit_nodes * 10 < t.nnodes);
  CHECK(uncovered(&t, x) == 0);
  CHECK(aabb_tree_segment_first(&t, p0, p1, AABB_SEG_ENTERING, INFINITY, &got) == 1);
  CHECK(got.tri == want.tri && got.t == want.t);
  uint32_t st;
  double d2 = scan_nearest(x, m.tris, m.ntris, p0, &st);
  aabb_nearest_t nr;
  CHECK(aabb_tree_nearest(&t, p0, INFINITY, &nr) == 1);
  CHECK(nr.tri == st && nr.dist2 == d2);

  /* Random motion: a few vertices jump across the margin each refit, all
   * creep; queries near the jumpers match the scan. */
  size_t fails = 0, queries = 0, leaves = 0;
  for (int round = 0; round < 200; round++) {
    uint32_t jump[4];
    for (int j = 0; j < 4; j++) {
      jump[j] = (uint32_t)(urand() * (double)m.nverts);
      for (int k = 0; k < 3; k++) x[3 * jump[j] + (uint32_t)k] += (urand() - 0.5) * 8 * mg;
    }
    for (size_t i = 0; i < 3 * m.nverts; i++) x[i] += (urand() - 0.5) * 0.05 * mg;
    aabb_tree_refit(&t, x);
    leaves += t.refit_leaves;
    fails += uncovered(&t, x) != 0;
    for (int j = 0; j < 4; j++) {
      double q[3];
      for (int k = 0; k < 3; k++) q[k] = x[3 * jump[j] + (uint32_t)k] + (urand() - 0.5) * 4 * mg;
      d2 = scan_nearest(x, m.tris, m.ntris, q, &st);
      fails += !aabb_tree_nearest(&t, q, INFINITY, &nr) || nr.tri != st || nr.dist2 != d2;
      queries++;
    }
  }
  printf("random motion: %zu queries, %zu failures, %.1f leaves per refit of %zu\n", queries, fails,
         (double)leaves / 200, t.nleaves);
  CHECK(fails == 0);
  CHECK(leaves < 200 * t.nleaves / 4);

  /* The whole organ shifted by two margins: every box, by the plain sweep. */
  for (size_t i = 0; i < 3 * m.nverts; i++) x[i] += 2 * mg;
  aabb_tree_refit(&t, x);
  CHECK(t.refit_leaves == t.nleaves && t.refit_nodes == t.nnodes);
  CHECK(uncovered(&t, x) == 0);
  d2 = scan_nearest(x, m.tris, m.ntris, p0, &st);
  CHECK(aabb_tree_nearest(&t, p0, INFINITY, &nr) == 1 && nr.tri == st && nr.dist2 == d2);

  /* Margin 0: tight boxes, recomputed in full at once, then on any motion. */
  aabb_tree_set_margin(&t, 0);
  aabb_tree_refit(&t, x);
  CHECK(t.refit_leaves == t.nleaves);
  x[3 * v] += 1e-9;
  aabb_tree_refit(&t, x);
  CHECK(t.refit_leaves >= 1 && t.refit_leaves <= t.vleaf_off[v + 1] - t.vleaf_off[v]);
  CHECK(uncovered(&t, x) == 0);

  /* The listed refit against the full one, on two trees over equal arrays. */
  aabb_tree_t ta, tb;
  double *xa = malloc(3 * m.nverts * sizeof *xa), *xb = malloc(3 * m.nverts * sizeof *xb);
  uint32_t *list = malloc((m.nverts + 1) * sizeof *list);
  memcpy(xa, m.pos, 3 * m.nverts * sizeof *xa);
  memcpy(xb, m.pos, 3 * m.nverts * sizeof *xb);
  CHECK(aabb_tree_build(&ta, xa, m.nverts, m.tris, m.ntris, &err) == 0);
  CHECK(aabb_tree_build(&tb, xb, m.nverts, m.tris, m.ntris, &err) == 0);
  size_t differ = 0, listed_leaves = 0;
  for (int round = 0; round < 100; round++) {
    size_t n = 0;
    /* Jumpers (some across the margin), creepers (below it), bystanders. */
    for (int j = 0; j < 40; j++) {
      uint32_t i = (uint32_t)(urand() * (double)m.nverts);
      double amp = j < 10 ? 6 * mg : 0.3 * mg;
      for (int k = 0; k < 3; k++) {
        double d = (urand() - 0.5) * amp;
        xa[3 * i + (uint32_t)k] += d;
        xb[3 * i + (uint32_t)k] += d;
      }
      list[n++] = i;
    }
    for (int j = 0; j < 10; j++) list[n++] = (uint32_t)(urand() * (double)m.nverts);
    list[n++] = (uint32_t)m.nverts; /* past the end: ignored */
    for (size_t a = n - 1; a > 0; a--) {
      size_t b = (size_t)(urand() * (double)(a + 1));
      uint32_t tmp = list[a];
      list[a] = list[b];
      list[b] = tmp;
    }
    aabb_tree_refit(&ta, xa);
    aabb_tree_refit_listed(&tb, xb, list, n);
    listed_leaves += tb.refit_leaves;
    differ += ta.refit_leaves != tb.refit_leaves || ta.refit_nodes != tb.refit_nodes ||
              memcmp(ta.nodes, tb.nodes, ta.nnodes * sizeof *ta.nodes) != 0 ||
              memcmp(ta.xr, tb.xr, 3 * m.nverts * sizeof *ta.xr) != 0 || memcmp(ta.lo, tb.lo, sizeof ta.lo) != 0 ||
              memcmp(ta.hi, tb.hi, sizeof ta.hi) != 0;
  }
  printf("listed refit: 100 rounds, %zu differ from the full refit, %zu leaves recomputed\n", differ, listed_leaves);
  CHECK(differ == 0 && listed_leaves > 0);
  /* A jumper left off the list: its leaves keep their old boxes. */
  uint32_t j0 = m.tris[0];
  for (int k = 0; k < 3; k++) xb[3 * j0 + (uint32_t)k] += 20 * mg;
  uint32_t other = m.tris[3 * (m.ntris / 2)];
  aabb_tree_refit_listed(&tb, xb, &other, 1);
  CHECK(uncovered(&tb, xb) > 0);
  aabb_tree_refit(&tb, xb);
  CHECK(uncovered(&tb, xb) == 0);
  aabb_tree_destroy(&ta);
  aabb_tree_destroy(&tb);
  free(xa);
  free(xb);
  free(list);

  free(moved);
  free(x);
  aabb_tree_destroy(&t);
  mesh_free(&m);
  return check_report("test_aabb_refit");
}
