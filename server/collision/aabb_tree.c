/* SPDX-License-Identifier: Apache-2.0 */
#include "collision/aabb_tree.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "vmath.h"

/* ---- build ---------------------------------------------------------------- */

typedef struct build_ctx {
  aabb_tree_t *t;
  const double *cent; /* 3 per triangle: centroids, the split keys */
  const double *tbox; /* 6 per triangle: lo xyz, hi xyz of its corners */
  uint32_t *idx;      /* triangle permutation being partitioned */
  size_t next;        /* next free node */
} build_ctx_t;

/* Rearranges idx[b, e) so that idx[k] holds the triangle whose centroid
 * coordinate on `axis` would be k-th in sorted order, with no larger key
 * before it and no smaller one after (quickselect, Hoare partition around a
 * median-of-three pivot: O(n) expected, no extra memory). */
static void select_kth(uint32_t *idx, const double *cent, int axis, ptrdiff_t b, ptrdiff_t e, ptrdiff_t k) {
#define KEY(i) cent[3 * (size_t)idx[i] + (size_t)axis]
  ptrdiff_t lo = b, hi = e - 1;
  while (lo < hi) {
    double ka = KEY(lo), kb = KEY(lo + (hi - lo) / 2), kc = KEY(hi);
    double p = ka < kb ? (kb < kc ? kb : (ka < kc ? kc : ka)) : (ka < kc ? ka : (kb < kc ? kc : kb));
    ptrdiff_t i = lo, j = hi;
    while (i <= j) { /* the pivot value is in the range, so both scans stop inside it */
      while (KEY(i) < p) i++;
      while (KEY(j) > p) j--;
      if (i <= j) {
        uint32_t tmp = idx[i];
        idx[i] = idx[j];
        idx[j] = tmp;
        i++;
        j--;
      }
    }
    /* Now [lo, j] <= p, [i, hi] >= p and everything strictly between equals p. */
    if (k <= j)
      hi = j;
    else if (k >= i)
      lo = i;
    else
      break;
  }
#undef KEY
}

/* Returns the reference of the subtree over slots [b, e): a leaf reference,
 * or the index of a node allocated before its children (pre-order). */
static uint32_t build_node(build_ctx_t *c, size_t b, size_t e, int level) {
  aabb_tree_t *t = c->t;
  if (level > t->depth) t->depth = level;
  size_t n = e - b;
  if (n <= AABB_TREE_LEAF_MAX) return AABB_LEAF | (uint32_t)n << 28 | (uint32_t)b;
  uint32_t self = (uint32_t)c->next++;
  /* Longest axis of the box around this node's triangles (docs/methods.md A §3.1). */
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t s = b; s < e; s++) {
    const double *tb = c->tbox + 6 * (size_t)c->idx[s];
    for (int k = 0; k < 3; k++) {
      lo[k] = tb[k] < lo[k] ? tb[k] : lo[k];
      hi[k] = tb[3 + k] > hi[k] ? tb[3 + k] : hi[k];
    }
  }
  int axis = 0;
  for (int k = 1; k < 3; k++)
    if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
  /* The median, moved up to a whole number of full leaves: the same
   * balance (depth ceil(log2(n / 4)) + 1), but leaves of four triangles
   * rather than two or three, so about a third fewer nodes to fetch. */
  size_t half = (n + 1) / 2;
  size_t mid = b + (half + AABB_TREE_LEAF_MAX - 1) / AABB_TREE_LEAF_MAX * AABB_TREE_LEAF_MAX;
  if (mid >= e) mid = b + half;
  select_kth(c->idx, c->cent, axis, (ptrdiff_t)b, (ptrdiff_t)e, (ptrdiff_t)mid);
  uint32_t left = build_node(c, b, mid, level + 1);
  uint32_t right = build_node(c, mid, e, level + 1);
  t->nodes[self].child[0] = left;
  t->nodes[self].child[1] = right;
  t->nodes[self].parent = UINT32_MAX; /* set by the caller for all but the root */
  t->nodes[self].unused = 0;
  if (!(left & AABB_LEAF)) t->nodes[left].parent = self;
  if (!(right & AABB_LEAF)) t->nodes[right].parent = self;
  return self;
}

/* Appends one leaf to refit's list: its distinct vertices, in first-use order. */
static void add_leaf(aabb_tree_t *t, uint32_t ref, uint32_t parent) {
  size_t l = t->nleaves++;
  uint32_t off = t->leaf_voff[l], nv = 0;
  const uint32_t *tv = t->tri_v + 3 * (size_t)AABB_LEAF_FIRST(ref);
  for (uint32_t i = 0; i < 3 * AABB_LEAF_COUNT(ref); i++) {
    uint32_t v = tv[i], j = 0;
    while (j < nv && t->leaf_vidx[off + j] != v) j++;
    if (j == nv) t->leaf_vidx[off + nv++] = v;
  }
  t->leaf_parent[l] = parent;
  t->leaf_voff[l + 1] = off + nv;
}

static int list_leaves(aabb_tree_t *t) {
  size_t maxleaves = t->nnodes + 1; /* a binary tree has one more leaf than internal nodes */
  t->leaf_parent = malloc(maxleaves * sizeof *t->leaf_parent);
  t->leaf_voff = malloc((maxleaves + 1) * sizeof *t->leaf_voff);
  t->leaf_vidx = malloc(3 * t->ntris * sizeof *t->leaf_vidx); /* at most every corner */
  if (!t->leaf_parent || !t->leaf_voff || !t->leaf_vidx) return -1;
  t->leaf_voff[0] = 0;
  if (!t->nnodes) add_leaf(t, t->root, UINT32_MAX);
  for (size_t i = 0; i < t->nnodes; i++)
    for (uint32_t c = 0; c < 2; c++)
      if (t->nodes[i].child[c] & AABB_LEAF) add_leaf(t, t->nodes[i].child[c], (uint32_t)i << 1 | c);
  size_t nref = t->leaf_voff[t->nleaves];
  uint32_t *shrunk = realloc(t->leaf_vidx, (nref ? nref : 1) * sizeof *shrunk);
  if (shrunk) t->leaf_vidx = shrunk;
  /* Each vertex's leaves (counting sort of the leaf lists by vertex), and
   * refit's scratch. */
  t->vleaf_off = calloc(t->nverts + 1, sizeof *t->vleaf_off);
  t->vleaf = malloc((nref ? nref : 1) * sizeof *t->vleaf);
  t->xr = malloc(3 * t->nverts * sizeof *t->xr);
  t->dirty = malloc(t->nleaves * sizeof *t->dirty);
  t->leaf_mark = calloc(t->nleaves, 1);
  t->node_mark = calloc(t->nnodes ? t->nnodes : 1, 1);
  t->vmoved = malloc((t->nverts ? t->nverts : 1) * sizeof *t->vmoved);
  if (!t->vleaf_off || !t->vleaf || !t->xr || !t->dirty || !t->leaf_mark || !t->node_mark || !t->vmoved) return -1;
  for (size_t i = 0; i < nref; i++) t->vleaf_off[t->leaf_vidx[i] + 1]++;
  for (size_t v = 0; v < t->nverts; v++) t->vleaf_off[v + 1] += t->vleaf_off[v];
  for (size_t l = 0; l < t->nleaves; l++)
    for (uint32_t i = t->leaf_voff[l]; i < t->leaf_voff[l + 1]; i++)
      t->vleaf[t->vleaf_off[t->leaf_vidx[i]]++] = (uint32_t)l;
  for (size_t v = t->nverts; v > 0; v--) t->vleaf_off[v] = t->vleaf_off[v - 1]; /* back to starts */
  t->vleaf_off[0] = 0;
  return 0;
}

int aabb_tree_build(aabb_tree_t *t, const double *x, size_t nverts, const uint32_t *tris, size_t ntris, verr_t *err) {
  memset(t, 0, sizeof *t);
  if (ntris == 0) return verr_set(err, "aabb_tree: no triangles");
  if (ntris > AABB_LEAF_FIRST(~0u))
    return verr_set(err, "aabb_tree: %zu triangles, more than leaf references hold (%u)", ntris, AABB_LEAF_FIRST(~0u));
  for (size_t i = 0; i < 3 * ntris; i++)
    if (tris[i] >= nverts)
      return verr_set(err, "aabb_tree: triangle %zu uses vertex %u of %zu", i / 3, (unsigned)tris[i], nverts);
  for (size_t i = 0; i < 3 * nverts; i++)
    if (!isfinite(x[i])) return verr_set(err, "aabb_tree: vertex %zu is not finite", i / 3);
  size_t maxnodes = ntris; /* internal nodes of a binary tree with at most ntris leaves, plus one */
  /* One node per cache line: a visit then costs one line, never two. */
  t->nodes = aligned_alloc(64, maxnodes * sizeof *t->nodes);
  t->tri_id = malloc(ntris * sizeof *t->tri_id);
  t->tri_v = malloc(3 * ntris * sizeof *t->tri_v);
  double *cent = malloc(3 * ntris * sizeof *cent), *tbox = malloc(6 * ntris * sizeof *tbox);
  if (!t->nodes || !t->tri_id || !t->tri_v || !cent || !tbox) {
    free(cent);
    free(tbox);
    aabb_tree_destroy(t);
    return verr_set(err, "aabb_tree: out of memory for %zu triangles", ntris);
  }
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < ntris; i++) {
    t->tri_id[i] = (uint32_t)i;
    for (int k = 0; k < 3; k++) {
      double s = 0, tl = INFINITY, th = -INFINITY;
      for (int v = 0; v < 3; v++) {
        double p = x[3 * (size_t)tris[3 * i + (size_t)v] + (size_t)k];
        s += p;
        tl = p < tl ? p : tl;
        th = p > th ? p : th;
      }
      cent[3 * i + (size_t)k] = s / 3;
      tbox[6 * i + (size_t)k] = tl;
      tbox[6 * i + 3 + (size_t)k] = th;
      lo[k] = tl < lo[k] ? tl : lo[k];
      hi[k] = th > hi[k] ? th : hi[k];
    }
  }
  t->ntris = ntris;
  t->nverts = nverts;
  build_ctx_t c = {t, cent, tbox, t->tri_id, 0};
  t->root = build_node(&c, 0, ntris, 1);
  t->nnodes = c.next;
  free(cent);
  free(tbox);
  if (t->depth >= AABB_TREE_STACK) { /* cannot happen with a median split; the query stacks rely on it */
    aabb_tree_destroy(t);
    return verr_set(err, "aabb_tree: depth over %d", AABB_TREE_STACK);
  }
  for (size_t s = 0; s < ntris; s++)
    for (int v = 0; v < 3; v++) t->tri_v[3 * s + (size_t)v] = tris[3 * (size_t)t->tri_id[s] + (size_t)v];
  if (list_leaves(t)) {
    aabb_tree_destroy(t);
    return verr_set(err, "aabb_tree: out of memory for %zu triangles", ntris);
  }
  /* Boxes are padded so that rounding in the box distance or slab test can
   * never prune a triangle the exact per-triangle test would accept (the
   * trees must agree with brute force). 1e-10 of the build's extent and
   * distance from the origin is ~1e-11 m for an organ: no measurable loss of
   * culling, and thousands of ulps of margin. */
  double mag = 0;
  for (int k = 0; k < 3; k++) mag = fmax(mag, fmax(fabs(lo[k]), fabs(hi[k])));
  t->pad = 1e-10 * (mag + v3_dist(lo, hi));
  double edges = 0;
  for (size_t i = 0; i < ntris; i++)
    for (int v = 0; v < 3; v++)
      edges += v3_dist(x + 3 * (size_t)tris[3 * i + (size_t)v], x + 3 * (size_t)tris[3 * i + (size_t)(v + 1) % 3]);
  aabb_tree_set_margin(t, AABB_TREE_MARGIN_EDGE * edges / (3.0 * (double)ntris));
  aabb_tree_refit(t, x);
  return 0;
}

void aabb_tree_set_margin(aabb_tree_t *t, double margin) {
  t->margin = margin >= 0 && isfinite(margin) ? margin : 0;
  t->full = 1;
}

void aabb_tree_destroy(aabb_tree_t *t) {
  free(t->nodes);
  free(t->tri_id);
  free(t->tri_v);
  free(t->leaf_parent);
  free(t->leaf_voff);
  free(t->leaf_vidx);
  free(t->vleaf_off);
  free(t->vleaf);
  free(t->xr);
  free(t->dirty);
  free(t->leaf_mark);
  free(t->node_mark);
  free(t->vmoved);
  memset(t, 0, sizeof *t);
}

/* ---- refit ---------------------------------------------------------------- */

/* Float bounds that contain the double ones: move outward by more than the
 * float rounding error (2^-24 relative) before rounding to nearest.
 * Infinities pass unchanged (inf - inf would be NaN): an empty box
 * (+inf, -inf) from a leaf whose coordinates are all NaN then stays empty
 * and never wins a min/max in the parent. */
static inline float float_down(double v) { return fabs(v) < INFINITY ? (float)(v - fabs(v) * 1.2e-7) : (float)v; }
static inline float float_up(double v) { return fabs(v) < INFINITY ? (float)(v + fabs(v) * 1.2e-7) : (float)v; }

/* Recomputes leaf l's box from its vertices' xr, fattened by the margin
 * and padded, into its parent's slot (or the root box for the only leaf).
 * The ternaries compile to branch-free min/max and skip NaN coordinates:
 * such a triangle can never win a query, exactly as in a brute-force scan. */
static void leaf_box(aabb_tree_t *t, size_t l, int mark) {
  const double *xr = t->xr;
  double l0 = INFINITY, l1 = INFINITY, l2 = INFINITY, h0 = -INFINITY, h1 = -INFINITY, h2 = -INFINITY;
  for (uint32_t i = t->leaf_voff[l]; i < t->leaf_voff[l + 1]; i++) {
    const double *p = xr + 3 * (size_t)t->leaf_vidx[i];
    double p0 = p[0], p1 = p[1], p2 = p[2];
    l0 = p0 < l0 ? p0 : l0;
    l1 = p1 < l1 ? p1 : l1;
    l2 = p2 < l2 ? p2 : l2;
    h0 = p0 > h0 ? p0 : h0;
    h1 = p1 > h1 ? p1 : h1;
    h2 = p2 > h2 ? p2 : h2;
  }
  double g = t->margin + t->pad;
  double lo[3] = {l0 - g, l1 - g, l2 - g}, hi[3] = {h0 + g, h1 + g, h2 + g};
  uint32_t parent = t->leaf_parent[l];
  if (parent == UINT32_MAX) { /* the only leaf: its box is the root's */
    for (int k = 0; k < 3; k++) {
      t->lo[k] = lo[k];
      t->hi[k] = hi[k];
    }
    return;
  }
  aabb_node_t *n = &t->nodes[parent >> 1];
  int c = (int)(parent & 1);
  for (int k = 0; k < 3; k++) {
    n->lo[k][c] = float_down(lo[k]);
    n->hi[k][c] = float_up(hi[k]);
  }
  /* Its path up, marked for the internal pass (stops at a marked node:
   * the rest of the path is marked already). */
  if (!mark) return;
  for (uint32_t u = parent >> 1; u != UINT32_MAX && !t->node_mark[u]; u = t->nodes[u].parent) t->node_mark[u] = 1;
}

/* Internal nodes bottom-up: all of them, or only the marked ones (marks
 * cleared). Pre-order layout: a node's children have larger indices, so
 * one backward sweep sees every child before its parent. */
static size_t sweep_nodes(aabb_tree_t *t, int all) {
  size_t nodes = 0;
  for (size_t i = t->nnodes; i-- > 0;) {
    if (!all && !t->node_mark[i]) continue;
    t->node_mark[i] = 0;
    nodes++;
    aabb_node_t *n = &t->nodes[i];
    for (int c = 0; c < 2; c++) {
      uint32_t ref = n->child[c];
      if (ref & AABB_LEAF) continue;
      const aabb_node_t *m = &t->nodes[ref];
      for (int k = 0; k < 3; k++) {
        n->lo[k][c] = m->lo[k][0] < m->lo[k][1] ? m->lo[k][0] : m->lo[k][1];
        n->hi[k][c] = m->hi[k][0] > m->hi[k][1] ? m->hi[k][0] : m->hi[k][1];
      }
    }
  }
  const aabb_node_t *r = &t->nodes[0];
  for (int k = 0; k < 3; k++) {
    t->lo[k] = r->lo[k][0] < r->lo[k][1] ? r->lo[k][0] : r->lo[k][1];
    t->hi[k] = r->hi[k][0] > r->hi[k][1] ? r->hi[k][0] : r->hi[k][1];
  }
  return nodes;
}

/* The refit over the vertices in cand (n of them), or over every vertex
 * when cand is NULL. */
static void refit(aabb_tree_t *t, const double *x, const uint32_t *cand, size_t n) {
  t->x = x;
  t->refit_leaves = t->refit_nodes = 0;
  int full = t->full;
  size_t nmoved = 0;
  if (!full) {
    /* A vertex has moved when some coordinate left [xr - m, xr + m]; the
     * negated test also takes NaN and infinite coordinates as moved. At
     * rest the branch is always predicted: one compare per vertex. */
    const double m = t->margin, *xr = t->xr;
    uint32_t *moved = t->vmoved;
    for (size_t a = 0; a < n; a++) {
      const size_t v = cand ? cand[a] : a;
      if (v >= t->nverts) continue;
      const double *p = x + 3 * v, *r = xr + 3 * v;
      if (fabs(p[0] - r[0]) <= m && fabs(p[1] - r[1]) <= m && fabs(p[2] - r[2]) <= m) continue;
      moved[nmoved++] = (uint32_t)v;
      if (nmoved * 8 > t->nverts) break; /* the sweep below: no need to look further */
    }
    if (!nmoved) return;
    /* Most of the organ moved: marking leaf by leaf would cost more than
     * the plain sweep over everything. */
    full = nmoved * 8 > t->nverts;
  }
  if (full) {
    memcpy(t->xr, x, 3 * t->nverts * sizeof *t->xr);
    for (size_t l = 0; l < t->nleaves; l++) leaf_box(t, l, 0);
    t->full = 0;
    t->refit_leaves = t->nleaves;
    if (t->nnodes) t->refit_nodes = sweep_nodes(t, 1);
    return;
  }
  size_t ndirty = 0;
  for (size_t a = 0; a < nmoved; a++) {
    uint32_t v = t->vmoved[a];
    memcpy(t->xr + 3 * (size_t)v, x + 3 * (size_t)v, 3 * sizeof *t->xr);
    for (uint32_t i = t->vleaf_off[v]; i < t->vleaf_off[v + 1]; i++) {
      uint32_t l = t->vleaf[i];
      if (t->leaf_mark[l]) continue;
      t->leaf_mark[l] = 1;
      t->dirty[ndirty++] = l;
    }
  }
  for (size_t i = 0; i < ndirty; i++) {
    t->leaf_mark[t->dirty[i]] = 0;
    leaf_box(t, t->dirty[i], 1);
  }
  t->refit_leaves = ndirty;
  if (t->nnodes) t->refit_nodes = sweep_nodes(t, 0);
}

void aabb_tree_refit(aabb_tree_t *t, const double *x) { refit(t, x, NULL, t->nverts); }

void aabb_tree_refit_listed(aabb_tree_t *t, const double *x, const uint32_t *idx, size_t n) {
  /* Another array: nothing is known about its unlisted vertices. (A tree
   * due a full refit sweeps everything whatever the list.) */
  if (x != t->x) idx = NULL, n = t->nverts;
  refit(t, x, idx, n);
}

/* ---- nearest point -------------------------------------------------------- */

/* Squared distance from q to [lo, hi] along one axis, zero inside. Written
 * as a clamp because compilers turn exactly this form into branch-free
 * max/min instructions: the comparisons of a traversal are data dependent,
 * and mispredicted branches cost more than the arithmetic. */
static inline double gap2(double lo, double hi, double q) {
  double c = q < lo ? lo : q;
  c = c > hi ? hi : c;
  return (q - c) * (q - c);
}

static inline double box_dist2(const double lo[3], const double hi[3], const double q[3]) {
  return gap2(lo[0], hi[0], q[0]) + gap2(lo[1], hi[1], q[1]) + gap2(lo[2], hi[2], q[2]);
}

static inline double child_dist2(const aabb_node_t *n, int c, const double q[3]) {
  return gap2(n->lo[0][c], n->hi[0][c], q[0]) + gap2(n->lo[1][c], n->hi[1][c], q[1]) +
         gap2(n->lo[2][c], n->hi[2][c], q[2]);
}

/* Starts fetching what visiting either child will read (its node, or a
 * leaf's vertex indices) while this node's boxes are being compared: the
 * traversal is bound by memory latency, not arithmetic. */
static inline void prefetch_children(const aabb_tree_t *t, const aabb_node_t *n) {
#if defined(__GNUC__)
  for (int c = 0; c < 2; c++) {
    uint32_t r = n->child[c];
    if (r & AABB_LEAF)
      __builtin_prefetch(t->tri_v + 3 * (size_t)AABB_LEAF_FIRST(r));
    else
      __builtin_prefetch(&t->nodes[r]);
  }
#else
  (void)t;
  (void)n;
#endif
}

typedef struct pending {
  uint32_t ref;
  double key; /* lower bound (squared distance or segment parameter) when pushed */
} pending_t;

typedef struct nearest_state {
  const aabb_tree_t *t;
  const double *q;
  double best;
  uint32_t best_tri, best_slot;
  int found;
  double bary[3], point[3];
} nearest_state_t;

static void nearest_leaf(nearest_state_t *st, uint32_t ref) {
  const aabb_tree_t *t = st->t;
  uint32_t first = AABB_LEAF_FIRST(ref), end = first + AABB_LEAF_COUNT(ref);
  const double *q = st->q;
  for (uint32_t s = first; s < end; s++) {
    const uint32_t *tv = t->tri_v + 3 * (size_t)s;
    const double *a = t->x + 3 * (size_t)tv[0], *b = t->x + 3 * (size_t)tv[1], *c = t->x + 3 * (size_t)tv[2];
    /* The triangle's own box first: a leaf's four triangles spread over
     * its box, and near the surface most of them are ruled out by this
     * branch-free bound at a third of the exact test's cost. */
    double lb = 0;
    for (int k = 0; k < 3; k++) {
      double lo = a[k] < b[k] ? a[k] : b[k], hi = a[k] > b[k] ? a[k] : b[k];
      lo = c[k] < lo ? c[k] : lo;
      hi = c[k] > hi ? c[k] : hi;
      lb += gap2(lo, hi, q[k]);
    }
    if (lb > st->best) continue;
    double cp[3], bary[3], d[3];
    tri_closest_point(q, a, b, c, cp, bary);
    v3_sub(d, cp, q);
    double d2 = v3_dot(d, d);
    /* The original index is fetched only for a winner or a tie. */
    if (d2 < st->best || (st->found && d2 == st->best && t->tri_id[s] < st->best_tri)) {
      st->best = d2;
      st->best_tri = t->tri_id[s];
      st->best_slot = s;
      st->found = 1;
      v3_copy(st->bary, bary);
      v3_copy(st->point, cp);
    }
  }
}

int aabb_tree_nearest(const aabb_tree_t *t, const double q[3], double max_dist2, aabb_nearest_t *out) {
  if (!t->ntris) return 0;
  nearest_state_t st = {t, q, max_dist2, UINT32_MAX, 0, 0, {0, 0, 0}, {0, 0, 0}};
  pending_t stack[AABB_TREE_STACK];
  int sp = 0;
  uint32_t ref = t->root;
  /* Ties are visited (>, not >=) so the lowest triangle index wins, as in a scan. */
  if (box_dist2(t->lo, t->hi, q) > st.best) return 0;
  for (;;) {
    if (ref & AABB_LEAF) {
      nearest_leaf(&st, ref);
    } else {
      /* Descend into the nearer child at once, so it tightens `best`
       * before the farther one is looked at; keep the farther for later. */
      const aabb_node_t *n = &t->nodes[ref];
      prefetch_children(t, n);
      double d0 = child_dist2(n, 0, q), d1 = child_dist2(n, 1, q);
      int nearc = d1 < d0;
      double dn = nearc ? d1 : d0, df = nearc ? d0 : d1;
      if (dn <= st.best) {
        if (df <= st.best) stack[sp++] = (pending_t){n->child[!nearc], df};
        ref = n->child[nearc];
        continue;
      }
    }
    for (;;) { /* the next pending subtree still within reach */
      if (!sp) goto done;
      pending_t e = stack[--sp];
      if (e.key <= st.best) {
        ref = e.ref;
        break;
      }
    }
  }
done:
  if (!st.found) return 0;
  out->tri = st.best_tri;
  out->dist2 = st.best;
  v3_copy(out->bary, st.bary);
  v3_copy(out->point, st.point);
  const uint32_t *tv = t->tri_v + 3 * (size_t)st.best_slot;
  const double *pa = t->x + 3 * (size_t)tv[0], *pb = t->x + 3 * (size_t)tv[1], *pc = t->x + 3 * (size_t)tv[2];
  double e1[3], e2[3], nrm[3], o[3];
  v3_sub(e1, pb, pa);
  v3_sub(e2, pc, pa);
  v3_cross(nrm, e1, e2);
  for (int k = 0; k < 3; k++) o[k] = q[k] - (pa[k] + pb[k] + pc[k]) / 3;
  out->behind = v3_dot(o, nrm) < 0;
  return 1;
}

/* ---- segment -------------------------------------------------------------- */

/* Slab test of p0 + s dir, s in [0, smax], against a box; writes the entry
 * parameter. Axes the segment runs parallel to are tested directly, so
 * 0 * inf never appears. */
static inline int seg_box(const double lo[3], const double hi[3], const double p0[3], const double dir[3],
                          const double inv[3], double smax, double *enter) {
  double s0 = 0, s1 = smax;
  for (int k = 0; k < 3; k++) {
    if (dir[k] == 0) {
      if (p0[k] < lo[k] || p0[k] > hi[k]) return 0;
      continue;
    }
    double a = (lo[k] - p0[k]) * inv[k], b = (hi[k] - p0[k]) * inv[k];
    if (a > b) {
      double tmp = a;
      a = b;
      b = tmp;
    }
    if (a > s0) s0 = a;
    if (b < s1) s1 = b;
    if (s0 > s1) return 0;
  }
  *enter = s0;
  return 1;
}

static inline int seg_child(const aabb_node_t *n, int c, const double p0[3], const double dir[3], const double inv[3],
                            double smax, double *enter) {
  double lo[3] = {n->lo[0][c], n->lo[1][c], n->lo[2][c]}, hi[3] = {n->hi[0][c], n->hi[1][c], n->hi[2][c]};
  return seg_box(lo, hi, p0, dir, inv, smax, enter);
}

int aabb_tree_segment_first(const aabb_tree_t *t, const double p0[3], const double p1[3], int flags, double t_max,
                            aabb_hit_t *out) {
  if (!t->ntris) return 0;
  double dir[3], inv[3];
  v3_sub(dir, p1, p0);
  for (int k = 0; k < 3; k++) inv[k] = dir[k] != 0 ? 1.0 / dir[k] : 0;
  double best = t_max;
  uint32_t best_tri = UINT32_MAX, best_slot = 0;
  int found = 0;
  double best_bary[3] = {0, 0, 0};
  pending_t stack[AABB_TREE_STACK];
  int sp = 0;
  double enter;
  if (!seg_box(t->lo, t->hi, p0, dir, inv, fmin(1.0, best), &enter)) return 0;
  uint32_t ref = t->root;
  for (;;) {
    if (ref & AABB_LEAF) {
      uint32_t first = AABB_LEAF_FIRST(ref), end = first + AABB_LEAF_COUNT(ref);
      for (uint32_t s = first; s < end; s++) {
        const uint32_t *tv = t->tri_v + 3 * (size_t)s;
        const double *a = t->x + 3 * (size_t)tv[0], *b = t->x + 3 * (size_t)tv[1], *c = t->x + 3 * (size_t)tv[2];
        double tt, bary[3];
        if (!seg_tri_intersect(p0, p1, a, b, c, &tt, bary)) continue;
        uint32_t id = t->tri_id[s];
        if (!(tt < best || (found && tt == best && id < best_tri))) continue;
        if (flags & AABB_SEG_ENTERING) {
          double e1[3], e2[3], nrm[3];
          v3_sub(e1, b, a);
          v3_sub(e2, c, a);
          v3_cross(nrm, e1, e2);
          if (v3_dot(dir, nrm) >= 0) continue; /* leaving (or grazing), not entering */
        }
        best = tt;
        best_tri = id;
        best_slot = s;
        found = 1;
        v3_copy(best_bary, bary);
      }
    } else {
      /* Front to back: the child the segment enters first is searched
       * first, and a hit there prunes every box entered later. */
      const aabb_node_t *n = &t->nodes[ref];
      prefetch_children(t, n);
      double smax = fmin(1.0, best), e0 = 0, e1 = 0;
      int h0 = seg_child(n, 0, p0, dir, inv, smax, &e0), h1 = seg_child(n, 1, p0, dir, inv, smax, &e1);
      if (h0 && h1) {
        int first = e1 < e0;
        stack[sp++] = (pending_t){n->child[!first], first ? e0 : e1};
        ref = n->child[first];
        continue;
      }
      if (h0 || h1) {
        ref = n->child[h1];
        continue;
      }
    }
    for (;;) {
      if (!sp) goto done;
      pending_t e = stack[--sp];
      if (e.key <= best) { /* ties still visited: the lowest index wins */
        ref = e.ref;
        break;
      }
    }
  }
done:
  if (!found) return 0;
  const uint32_t *tv = t->tri_v + 3 * (size_t)best_slot;
  out->tri = best_tri;
  out->t = best;
  v3_copy(out->bary, best_bary);
  for (int k = 0; k < 3; k++) out->point[k] = p0[k] + best * dir[k];
  double dmin = INFINITY;
  out->vertex = tv[0];
  for (int v = 0; v < 3; v++) {
    double d = v3_dist(t->x + 3 * (size_t)tv[v], out->point);
    if (d < dmin) {
      dmin = d;
      out->vertex = tv[v];
    }
  }
  return 1;
}

/* ---- box ------------------------------------------------------------------ */

int tri_box_overlap(const double a[3], const double b[3], const double c[3], const double lo[3], const double hi[3]) {
  /* Only finite, non-empty boxes select anything, and a triangle with a NaN
   * corner overlaps nothing (NaN would fail every separation test). */
  for (int k = 0; k < 3; k++)
    if (!(lo[k] <= hi[k]) || !isfinite(lo[k]) || !isfinite(hi[k]) || isnan(a[k]) || isnan(b[k]) || isnan(c[k]))
      return 0;
  double ctr[3], h[3], v[3][3], e[3][3];
  for (int k = 0; k < 3; k++) {
    ctr[k] = 0.5 * (lo[k] + hi[k]);
    h[k] = 0.5 * (hi[k] - lo[k]);
    v[0][k] = a[k] - ctr[k];
    v[1][k] = b[k] - ctr[k];
    v[2][k] = c[k] - ctr[k];
  }
  /* The box's own axes: the triangle's extent against the half-widths. */
  for (int k = 0; k < 3; k++) {
    double mn = fmin(v[0][k], fmin(v[1][k], v[2][k])), mx = fmax(v[0][k], fmax(v[1][k], v[2][k]));
    if (mn > h[k] || mx < -h[k]) return 0;
  }
  for (int i = 0; i < 3; i++) v3_sub(e[i], v[(i + 1) % 3], v[i]);
  /* The triangle's plane: the box's projection radius on the normal. */
  double nrm[3];
  v3_cross(nrm, e[0], e[1]);
  double r = h[0] * fabs(nrm[0]) + h[1] * fabs(nrm[1]) + h[2] * fabs(nrm[2]);
  if (fabs(v3_dot(nrm, v[0])) > r) return 0;
  /* Edge x box axis: the nine axes that separate edge-edge configurations.
   * A zero axis (edge parallel to a box axis) projects everything to 0 and
   * separates nothing, which is the right answer. */
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++) {
      double u[3] = {0, 0, 0}, ax[3];
      u[k] = 1;
      v3_cross(ax, u, e[i]);
      double p0 = v3_dot(ax, v[0]), p1 = v3_dot(ax, v[1]), p2 = v3_dot(ax, v[2]);
      double mn = fmin(p0, fmin(p1, p2)), mx = fmax(p0, fmax(p1, p2));
      double rad = h[0] * fabs(ax[0]) + h[1] * fabs(ax[1]) + h[2] * fabs(ax[2]);
      if (mn > rad || mx < -rad) return 0;
    }
  return 1;
}

static inline int boxes_overlap(const double alo[3], const double ahi[3], const double blo[3], const double bhi[3]) {
  return !(alo[0] > bhi[0] || ahi[0] < blo[0] || alo[1] > bhi[1] || ahi[1] < blo[1] || alo[2] > bhi[2] ||
           ahi[2] < blo[2]);
}

/* Every leaf whose box overlaps [lo, hi], child 0 first (so leaves come in
 * leaf order): leaf(ctx, first slot, count). Nothing when the root's box
 * misses it (a NaN bound misses). */
typedef void (*leaf_fn)(const aabb_tree_t *t, uint32_t first, uint32_t count, void *ctx);
static void walk_box(const aabb_tree_t *t, const double lo[3], const double hi[3], leaf_fn leaf, void *ctx) {
  if (!t->ntris) return;
  for (int k = 0; k < 3; k++)
    if (!(t->lo[k] <= hi[k] && t->hi[k] >= lo[k])) return;
  uint32_t stack[AABB_TREE_STACK];
  int sp = 0;
  stack[sp++] = t->root;
  while (sp) {
    uint32_t ref = stack[--sp];
    if (ref & AABB_LEAF) {
      leaf(t, AABB_LEAF_FIRST(ref), AABB_LEAF_COUNT(ref), ctx);
      continue;
    }
    const aabb_node_t *n = &t->nodes[ref];
    for (int c = 1; c >= 0; c--) {
      double clo[3] = {n->lo[0][c], n->lo[1][c], n->lo[2][c]}, chi[3] = {n->hi[0][c], n->hi[1][c], n->hi[2][c]};
      if (boxes_overlap(clo, chi, lo, hi)) stack[sp++] = n->child[c];
    }
  }
}

typedef struct box_query_ctx {
  const double *lo, *hi;
  uint32_t *out;
  size_t cap, count;
} box_query_ctx_t;

static void query_leaf(const aabb_tree_t *t, uint32_t first, uint32_t count, void *vctx) {
  box_query_ctx_t *q = vctx;
  for (uint32_t s = first; s < first + count; s++) {
    const uint32_t *tv = t->tri_v + 3 * (size_t)s;
    if (!tri_box_overlap(t->x + 3 * (size_t)tv[0], t->x + 3 * (size_t)tv[1], t->x + 3 * (size_t)tv[2], q->lo, q->hi))
      continue;
    if (q->count < q->cap) q->out[q->count] = t->tri_id[s];
    q->count++;
  }
}

size_t aabb_tree_box_query(const aabb_tree_t *t, const double lo[3], const double hi[3], uint32_t *out, size_t cap) {
  for (int k = 0; k < 3; k++)
    if (!(lo[k] <= hi[k]) || !isfinite(lo[k]) || !isfinite(hi[k])) return 0; /* as tri_box_overlap */
  box_query_ctx_t q = {lo, hi, out, cap, 0};
  walk_box(t, lo, hi, query_leaf, &q);
  return q.count;
}

typedef struct corners_ctx {
  const double *lo, *hi;
  aabb_corner_fn fn;
  void *ctx;
} corners_ctx_t;

static void corners_leaf(const aabb_tree_t *t, uint32_t first, uint32_t count, void *vctx) {
  const corners_ctx_t *c = vctx;
  const uint32_t *tv = t->tri_v + 3 * (size_t)first;
  for (uint32_t k = 0; k < 3 * count; k++) {
    const double *p = t->x + 3 * (size_t)tv[k];
    if (p[0] >= c->lo[0] && p[0] <= c->hi[0] && p[1] >= c->lo[1] && p[1] <= c->hi[1] && p[2] >= c->lo[2] &&
        p[2] <= c->hi[2])
      c->fn(c->ctx, tv[k]);
  }
}

void aabb_tree_box_corners(const aabb_tree_t *t, const double lo[3], const double hi[3], aabb_corner_fn fn, void *ctx) {
  corners_ctx_t c = {lo, hi, fn, ctx};
  walk_box(t, lo, hi, corners_leaf, &c);
}
