/* SPDX-License-Identifier: Apache-2.0 */
#include "interaction/shaft.h"

#include <math.h>

#include "collision/cylinder.h"
#include "vmath.h"

void shaft_axis(const double q[4], double axis[3]) {
  double w = q[0], x = q[1], y = q[2], z = q[3];
  /* Third column of the rotation matrix: R e_z. */
  v3_set(axis, 2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y));
  if (!(v3_normalize(axis) > 0.5)) v3_set(axis, 0, 0, 1); /* not a rotation: keep the tool upright */
}

void shaft_segment(const double tip[3], const double axis[3], double tip_radius, double length, double p0[3],
                   double p1[3]) {
  /* The shaft starts where it leaves the tip sphere: the sphere is the
   * god-object's business, the shaft must not fight it. */
  double start = fmin(tip_radius * (1 + SHAFT_RADIUS_FRACTION), length);
  v3_copy(p0, tip);
  v3_axpy(p0, axis, start);
  v3_copy(p1, tip);
  v3_axpy(p1, axis, length);
}

/* One vertex of the node test (the scan and the candidate list run this
 * same code, so their forces agree to the bit): 1 when pushed. */
static int push_node(const cylinder_t *c, const double lo[3], const double hi[3], double k, const double *x, uint32_t i,
                     shaft_add_fn add, void *ctx, double f_tool[3]) {
  const double *v = x + 3 * (size_t)i;
  if (v[0] < lo[0] || v[0] > hi[0] || v[1] < lo[1] || v[1] > hi[1] || v[2] < lo[2] || v[2] > hi[2]) return 0;
  cylinder_hit_t h;
  if (!cylinder_test_node(c, v, &h) || v3_norm(h.dir) < 0.5) return 0; /* on the axis: no direction */
  double mag = fmin(k * (c->radius - h.dist), SHAFT_MAX_VERTEX_FORCE), f[3];
  v3_scale(f, h.dir, -mag); /* dir points to the axis: push the other way */
  add(ctx, i, f);
  v3_axpy(f_tool, f, -1);
  return 1;
}

/* The cylinder and its broad-phase box: the shaft's box, grown by the
 * radius. */
static void node_test_setup(const double p0[3], const double p1[3], double radius, cylinder_t *c, double lo[3],
                            double hi[3]) {
  v3_copy(c->p0, p0);
  v3_copy(c->p1, p1);
  c->radius = radius;
  for (int j = 0; j < 3; j++) {
    lo[j] = fmin(p0[j], p1[j]) - radius;
    hi[j] = fmax(p0[j], p1[j]) + radius;
  }
}

size_t shaft_push(const double p0[3], const double p1[3], double radius, double k, const double *x, size_t n,
                  shaft_add_fn add, void *ctx, double f_tool[3]) {
  cylinder_t c;
  double lo[3], hi[3];
  node_test_setup(p0, p1, radius, &c, lo, hi);
  size_t hits = 0;
  for (size_t i = 0; i < n; i++) hits += (size_t)push_node(&c, lo, hi, k, x, (uint32_t)i, add, ctx, f_tool);
  return hits;
}

size_t shaft_push_list(const double p0[3], const double p1[3], double radius, double k, const double *x,
                       const uint32_t *idx, size_t nidx, shaft_add_fn add, void *ctx, double f_tool[3]) {
  cylinder_t c;
  double lo[3], hi[3];
  node_test_setup(p0, p1, radius, &c, lo, hi);
  size_t hits = 0;
  for (size_t j = 0; j < nidx; j++) hits += (size_t)push_node(&c, lo, hi, k, x, idx[j], add, ctx, f_tool);
  return hits;
}

/* Box queries answer into this many slots; a piece of the segment with more
 * candidates is halved, down to SHAFT_SPLIT_DEPTH halvings, below which the
 * piece scans every triangle (a mesh crumpled into one spot). */
#define SHAFT_QUERY_CAP 64
#define SHAFT_SPLIT_DEPTH 12
#define SHAFT_MAX_PIECES 256
/* Each piece's box covers the segment a little past its ends, so that a
 * triangle whose computed crossing parameter rounds into the piece is in
 * the box even if its exact one lies just outside (rounding is far below). */
#define SHAFT_PIECE_OVERLAP 1e-6

typedef struct crossings {
  uint32_t *tri;
  double *t;
  double (*bary)[3];
  size_t n, cap;
} crossings_t;

/* Keeps the cap first crossings by (t, triangle), whatever order they come
 * in: the tree and the scan then agree exactly. */
static void keep(crossings_t *c, uint32_t tri, double t, const double bary[3]) {
  size_t i = c->n;
  while (i > 0 && (c->t[i - 1] > t || (c->t[i - 1] == t && c->tri[i - 1] > tri))) i--;
  if (i >= c->cap) return;
  size_t last = c->n < c->cap ? c->n : c->cap - 1;
  for (size_t j = last; j > i; j--) {
    c->tri[j] = c->tri[j - 1];
    c->t[j] = c->t[j - 1];
    v3_copy(c->bary[j], c->bary[j - 1]);
  }
  c->tri[i] = tri;
  c->t[i] = t;
  v3_copy(c->bary[i], bary);
  if (c->n < c->cap) c->n++;
}

/* Tests triangle tri against the whole segment (as the scan does) and keeps
 * it if it is crossed within the piece [ta, tb) ([ta, tb] for the last
 * piece): every crossing belongs to exactly one piece. */
static void test_tri(const double p0[3], const double p1[3], const shaft_surface_t *s, uint32_t tri, double ta,
                     double tb, int last, crossings_t *c) {
  const uint32_t *v = s->tris + 3 * (size_t)tri;
  double t, bary[3];
  if (!seg_tri_intersect(p0, p1, s->x + 3 * (size_t)v[0], s->x + 3 * (size_t)v[1], s->x + 3 * (size_t)v[2], &t, bary))
    return;
  if (t >= ta && (t < tb || (last && t <= tb))) keep(c, tri, t, bary);
}

/* Finds the crossings in [ta, tb) ([ta, tb] if last) of which only the
 * part [clo, chi] can hold any (the segment clipped to the tree's box). */
static void piece(const double p0[3], const double p1[3], const shaft_surface_t *s, double ta, double tb, int last,
                  double clo, double chi, int depth, crossings_t *c) {
  if (!s->tree || depth > SHAFT_SPLIT_DEPTH) {
    for (size_t i = 0; i < s->ntris; i++) test_tri(p0, p1, s, (uint32_t)i, ta, tb, last, c);
    return;
  }
  double ua = fmax(ta, clo), ub = fmin(tb, chi);
  if (ua > ub) return;
  double a[3], b[3], d[3], lo[3], hi[3], pad = 0;
  v3_sub(d, p1, p0);
  v3_copy(a, p0);
  v3_axpy(a, d, ua - SHAFT_PIECE_OVERLAP);
  v3_copy(b, p0);
  v3_axpy(b, d, ub + SHAFT_PIECE_OVERLAP);
  for (int j = 0; j < 3; j++) pad = fmax(pad, fmax(fabs(a[j]), fabs(b[j])));
  /* Rounding of the piece's ends, and how far the surface may have moved
   * since the boxes were fit (a triangle moved by at most slack still meets
   * the grown box inside its stale leaf box). */
  pad = pad * 1e-12 + s->slack;
  for (int j = 0; j < 3; j++) {
    lo[j] = fmin(a[j], b[j]) - pad;
    hi[j] = fmax(a[j], b[j]) + pad;
  }
  uint32_t cand[SHAFT_QUERY_CAP];
  size_t n = aabb_tree_box_query(s->tree, lo, hi, cand, SHAFT_QUERY_CAP);
  if (n > SHAFT_QUERY_CAP) {
    double tm = 0.5 * (ua + ub);
    piece(p0, p1, s, ta, tm, 0, clo, chi, depth + 1, c);
    piece(p0, p1, s, tm, tb, last, clo, chi, depth + 1, c);
    return;
  }
  for (size_t i = 0; i < n; i++) test_tri(p0, p1, s, cand[i], ta, tb, last, c);
}

size_t shaft_crossings(const double p0[3], const double p1[3], const shaft_surface_t *s, uint32_t *tri, double *t,
                       double (*bary)[3], size_t cap) {
  crossings_t c = {tri, t, bary, 0, cap < SHAFT_MAX_CROSSINGS ? cap : SHAFT_MAX_CROSSINGS};
  if (c.cap == 0 || s->ntris == 0) return 0;
  /* A tree over another surface (a topology change the caller missed)
   * would index past x: scan instead. */
  const aabb_tree_t *tree = s->tree;
  shaft_surface_t scan = *s;
  if (tree && (tree->ntris != s->ntris || tree->nverts != s->n)) scan.tree = NULL;
  double clo = 0, chi = 1;
  if (scan.tree) {
    /* Clip to the root box (grown like the pieces' boxes): every crossing
     * point lies in it, and the pieces then start small. */
    double g = scan.slack + 1e-9 * (v3_norm(scan.tree->lo) + v3_norm(scan.tree->hi) + v3_dist(p0, p1));
    for (int j = 0; j < 3 && clo <= chi; j++) {
      double d = p1[j] - p0[j], lo = scan.tree->lo[j] - g, hi = scan.tree->hi[j] + g;
      if (d == 0) {
        if (!(p0[j] >= lo && p0[j] <= hi)) chi = -1;
        continue;
      }
      double t0 = (lo - p0[j]) / d, t1 = (hi - p0[j]) / d;
      clo = fmax(clo, fmin(t0, t1) - SHAFT_PIECE_OVERLAP);
      chi = fmin(chi, fmax(t0, t1) + SHAFT_PIECE_OVERLAP);
    }
    if (!(clo <= chi)) return 0; /* also a NaN segment */
  }
  /* Start from pieces about two leaf boxes long (a leaf's few triangles on
   * a surface spanning the root box) plus the slack: a box query costs what
   * it overlaps, so one query over a long shaft's whole box would cost more
   * than the scan (kidney, 10 cm shaft through it: 29 us that way, 7-9 us
   * in pieces; 1 to 4 leaf lengths measured alike within noise). */
  size_t np = 1;
  if (scan.tree) {
    double ext = fmax(scan.tree->hi[0] - scan.tree->lo[0],
                      fmax(scan.tree->hi[1] - scan.tree->lo[1], scan.tree->hi[2] - scan.tree->lo[2]));
    double leaf = ext * sqrt(2.0 * AABB_TREE_LEAF_MAX / (double)scan.tree->ntris);
    double want = v3_dist(p0, p1) * (chi - clo) / (2 * leaf + 2 * scan.slack);
    np = want >= SHAFT_MAX_PIECES ? SHAFT_MAX_PIECES : want >= 1 ? (size_t)ceil(want) : 1;
  }
  for (size_t i = 0; i < np; i++) {
    double ta = i == 0 ? 0 : clo + (chi - clo) * (double)i / (double)np;
    double tb = i + 1 == np ? 1 : clo + (chi - clo) * (double)(i + 1) / (double)np;
    piece(p0, p1, &scan, ta, tb, i + 1 == np, clo, chi, 0, &c);
  }
  return c.n;
}

size_t shaft_contact(const double p0[3], const double p1[3], double radius, double k, const shaft_surface_t *s,
                     shaft_add_fn add, void *ctx, double f_tool[3], shaft_stats_t *st) {
  size_t nodes = s->cand ? shaft_push_list(p0, p1, radius, k, s->x, s->cand, s->ncand, add, ctx, f_tool)
                         : shaft_push(p0, p1, radius, k, s->x, s->n, add, ctx, f_tool);
  uint32_t tri[SHAFT_MAX_CROSSINGS];
  double tc[SHAFT_MAX_CROSSINGS], bary[SHAFT_MAX_CROSSINGS][3];
  size_t nc = shaft_crossings(p0, p1, s, tri, tc, bary, SHAFT_MAX_CROSSINGS);
  /* Distinct corners and their summed shares, in order of first use. */
  uint32_t cv[3 * SHAFT_MAX_CROSSINGS];
  double cf[3 * SHAFT_MAX_CROSSINGS][3];
  size_t ncv = 0;
  cylinder_t cyl;
  v3_copy(cyl.p0, p0);
  v3_copy(cyl.p1, p1);
  cyl.radius = radius;
  double ax[3];
  v3_sub(ax, p1, p0);
  v3_normalize(ax); /* crossings exist only for a segment of positive length */
  /* The crossing point is on the axis: a full radius deep. */
  double fmag = fmin(k * radius, SHAFT_MAX_VERTEX_FORCE);
  for (size_t c = 0; c < nc; c++) {
    const uint32_t *v = s->tris + 3 * (size_t)tri[c];
    const double *a = s->x + 3 * (size_t)v[0], *b = s->x + 3 * (size_t)v[1], *cc = s->x + 3 * (size_t)v[2];
    double e1[3], e2[3], nrm[3], u[3];
    v3_sub(e1, b, a);
    v3_sub(e2, cc, a);
    v3_cross(nrm, e1, e2);
    /* Inward normal, less its part along the axis. */
    v3_scale(u, nrm, -1);
    v3_axpy(u, ax, -v3_dot(u, ax));
    int head_on = !(v3_norm(u) > 1e-6 * v3_norm(nrm));
    if (!head_on) v3_normalize(u);
    for (int j = 0; j < 3; j++) {
      const double *p = s->x + 3 * (size_t)v[j];
      cylinder_hit_t h;
      if (cylinder_test_node(&cyl, p, &h)) continue; /* the node test has it */
      double dir[3];
      if (head_on) {
        /* Radially away from the axis: the corner is outside the cylinder. */
        v3_sub(dir, p, p0);
        v3_axpy(dir, ax, -v3_dot(dir, ax));
        if (!(v3_normalize(dir) > 0)) continue;
      } else {
        v3_copy(dir, u);
      }
      size_t q = 0;
      while (q < ncv && cv[q] != v[j]) q++;
      if (q == ncv) {
        cv[ncv] = v[j];
        v3_set(cf[ncv], 0, 0, 0);
        ncv++;
      }
      v3_axpy(cf[q], dir, bary[c][j] * fmag);
    }
  }
  size_t pushed = 0;
  for (size_t q = 0; q < ncv; q++) {
    double mag = v3_norm(cf[q]);
    if (!(mag > 0)) continue; /* a corner with no share (crossing on the opposite edge) */
    if (mag > SHAFT_MAX_VERTEX_FORCE) v3_scale(cf[q], cf[q], SHAFT_MAX_VERTEX_FORCE / mag);
    add(ctx, cv[q], cf[q]);
    v3_axpy(f_tool, cf[q], -1);
    pushed++;
  }
  if (st) {
    st->nodes = nodes;
    st->crossings = nc;
    st->corners = pushed;
  }
  return nodes + pushed;
}
