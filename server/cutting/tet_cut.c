/* SPDX-License-Identifier: Apache-2.0 */
#include "cutting/tet_cut.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cutting/tet_split.h"
#include "state_blob.h"
#include "tet_mesh.h"
#include "vmath.h"
#include "vtime.h"

static double now_s(void) { return (double)vtime_mono_ns() * 1e-9; }

#define TC_PENDING 1u
#define TC_FROZEN 2u
/* Face keys pack three node ids of 21 bits each. */
#define TC_MAX_NODES ((size_t)1 << 21)
/* One tetrahedron with all six edges cut bisects into at most 2^6 leaves. */
#define TC_MAX_LEAVES 64
#define TC_NONE UINT32_MAX

typedef struct eslot {
  uint64_t key; /* (i << 32) | j, i < j; 0 = empty */
  uint32_t node, seq;
  double t; /* from node i */
} eslot_t;

typedef struct spoint {
  uint32_t node, i, j;
} spoint_t;

struct tet_cut_priv {
  eslot_t *eh;
  size_t eh_cap, eh_count;
  uint32_t seq;
  uint64_t *fh; /* cut faces, 0 = empty */
  size_t fh_cap, fh_count;
  uint32_t *pend;
  size_t npend, cap_pend;
  uint32_t *n2t_start, *n2t; /* node -> tetrahedra */
  size_t n2t_cap_n, n2t_cap_t;
  spoint_t *spts; /* new points of this cut not yet examined for opening */
  size_t nspts, cap_spts;
  int active;
  double tip[3], handle[3];
};

/* ---- small hash sets ----------------------------------------------------- */

static uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

static eslot_t *edge_find(const struct tet_cut_priv *p, uint32_t a, uint32_t b) {
  if (!p->eh_count) return NULL;
  uint64_t key = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
  size_t m = p->eh_cap - 1;
  for (size_t h = mix64(key) & m;; h = (h + 1) & m) {
    if (p->eh[h].key == key) return &p->eh[h];
    if (!p->eh[h].key) return NULL;
  }
}

static int edge_grow(struct tet_cut_priv *p) {
  size_t cap = p->eh_cap ? 2 * p->eh_cap : 256;
  eslot_t *n = calloc(cap, sizeof *n);
  if (!n) return -1;
  for (size_t s = 0; s < p->eh_cap; s++) {
    if (!p->eh[s].key) continue;
    size_t h = mix64(p->eh[s].key) & (cap - 1);
    while (n[h].key) h = (h + 1) & (cap - 1);
    n[h] = p->eh[s];
  }
  free(p->eh);
  p->eh = n;
  p->eh_cap = cap;
  return 0;
}

static eslot_t *edge_insert(struct tet_cut_priv *p, uint32_t a, uint32_t b) {
  if (2 * (p->eh_count + 1) > p->eh_cap && edge_grow(p)) return NULL;
  uint64_t key = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
  size_t m = p->eh_cap - 1, h = mix64(key) & m;
  while (p->eh[h].key) h = (h + 1) & m;
  p->eh[h].key = key;
  p->eh[h].node = TC_NONE;
  p->eh[h].seq = p->seq++;
  p->eh_count++;
  return &p->eh[h];
}

static uint64_t face_key(uint32_t a, uint32_t b, uint32_t c) {
  uint32_t t;
  if (a > b) t = a, a = b, b = t;
  if (b > c) t = b, b = c, c = t;
  if (a > b) t = a, a = b, b = t;
  return (uint64_t)a << 42 | (uint64_t)b << 21 | c;
}

static int face_has(const struct tet_cut_priv *p, uint64_t key) {
  if (!p->fh_count) return 0;
  size_t m = p->fh_cap - 1;
  for (size_t h = mix64(key) & m;; h = (h + 1) & m) {
    if (p->fh[h] == key) return 1;
    if (!p->fh[h]) return 0;
  }
}

static int face_add(struct tet_cut_priv *p, uint64_t key) {
  if (face_has(p, key)) return 0;
  if (2 * (p->fh_count + 1) > p->fh_cap) {
    size_t cap = p->fh_cap ? 2 * p->fh_cap : 256;
    uint64_t *n = calloc(cap, sizeof *n);
    if (!n) return -1;
    for (size_t s = 0; s < p->fh_cap; s++) {
      if (!p->fh[s]) continue;
      size_t h = mix64(p->fh[s]) & (cap - 1);
      while (n[h]) h = (h + 1) & (cap - 1);
      n[h] = p->fh[s];
    }
    free(p->fh);
    p->fh = n;
    p->fh_cap = cap;
  }
  size_t m = p->fh_cap - 1, h = mix64(key) & m;
  while (p->fh[h]) h = (h + 1) & m;
  p->fh[h] = key;
  p->fh_count++;
  return 0;
}

/* ---- growable mesh -------------------------------------------------------- */

static int grow(void **ptr, size_t elem, size_t cap) {
  void *n = realloc(*ptr, cap * elem);
  if (!n) return -1;
  *ptr = n;
  return 0;
}

/* Room for `extra` more nodes and `extra_t` more tetrahedra, by doubling. */
static int reserve(tet_cut_t *c, size_t extra, size_t extra_t) {
  if (c->n + extra >= TC_MAX_NODES) return -1;
  if (c->n + extra > c->cap_n) {
    size_t cap = c->cap_n ? c->cap_n : 64;
    while (cap < c->n + extra) cap *= 2;
    if (grow((void **)&c->x, 3 * sizeof(double), cap) || grow((void **)&c->x_rest, 3 * sizeof(double), cap) ||
        grow((void **)&c->v, 3 * sizeof(double), cap) || grow((void **)&c->attr, 2 * sizeof(double), cap) ||
        grow((void **)&c->fixed, 1, cap))
      return -1;
    c->cap_n = cap;
  }
  if (c->ntets + extra_t > c->cap_t) {
    size_t cap = c->cap_t ? c->cap_t : 64;
    while (cap < c->ntets + extra_t) cap *= 2;
    if (grow((void **)&c->tet, 4 * sizeof(uint32_t), cap) || grow((void **)&c->tflag, 1, cap)) return -1;
    c->cap_t = cap;
  }
  return 0;
}

/* Node -> tetrahedra incidence (CSR), rebuilt after topology changes. */
static int build_n2t(tet_cut_t *c) {
  struct tet_cut_priv *p = c->priv;
  if (p->n2t_cap_n < c->n + 1) {
    if (grow((void **)&p->n2t_start, sizeof(uint32_t), c->cap_n + 1)) return -1;
    p->n2t_cap_n = c->cap_n + 1;
  }
  if (p->n2t_cap_t < 4 * c->ntets) {
    if (grow((void **)&p->n2t, sizeof(uint32_t), 4 * c->cap_t)) return -1;
    p->n2t_cap_t = 4 * c->cap_t;
  }
  uint32_t *st = p->n2t_start;
  memset(st, 0, (c->n + 1) * sizeof *st);
  for (size_t k = 0; k < 4 * c->ntets; k++) st[c->tet[k] + 1]++;
  for (size_t i = 0; i < c->n; i++) st[i + 1] += st[i];
  for (size_t t = 0; t < c->ntets; t++)
    for (int k = 0; k < 4; k++) p->n2t[st[c->tet[4 * t + k]]++] = (uint32_t)t;
  for (size_t i = c->n; i > 0; i--) st[i] = st[i - 1];
  st[0] = 0;
  return 0;
}

static int tet_has(const uint32_t *q, uint32_t a) { return q[0] == a || q[1] == a || q[2] == a || q[3] == a; }

int tet_cut_create(tet_cut_t *c, size_t n, const double *x_rest, const double *x, const double *v, const uint8_t *fixed,
                   size_t ntets, const uint32_t *tets, verr_t *err) {
  memset(c, 0, sizeof *c);
  if (n == 0 || ntets == 0) return verr_set(err, "tet_cut: empty mesh (%zu nodes, %zu tetrahedra)", n, ntets);
  if (n >= TC_MAX_NODES / 2) return verr_set(err, "tet_cut: too many nodes (%zu, at most %zu)", n, TC_MAX_NODES / 2);
  for (size_t k = 0; k < 4 * ntets; k++)
    if (tets[k] >= n) return verr_set(err, "tet_cut: tetrahedron %zu refers to node %u of %zu", k / 4, tets[k], n);
  for (size_t k = 0; k < 3 * n; k++)
    if (!isfinite(x_rest[k]) || (x && !isfinite(x[k])) || (v && !isfinite(v[k])))
      return verr_set(err, "tet_cut: node %zu has a non-finite coordinate", k / 3);
  c->priv = calloc(1, sizeof *c->priv);
  c->snap = 0.25;
  if (!c->priv || reserve(c, 2 * n, 2 * ntets)) {
    tet_cut_destroy(c);
    return verr_set(err, "tet_cut: out of memory for %zu nodes", n);
  }
  c->n = n;
  c->ntets = ntets;
  memcpy(c->x_rest, x_rest, 3 * n * sizeof(double));
  memcpy(c->x, x ? x : x_rest, 3 * n * sizeof(double));
  if (v)
    memcpy(c->v, v, 3 * n * sizeof(double));
  else
    memset(c->v, 0, 3 * n * sizeof(double));
  if (fixed)
    memcpy(c->fixed, fixed, n);
  else
    memset(c->fixed, 0, n);
  memcpy(c->tet, tets, 4 * ntets * sizeof(uint32_t));
  memset(c->tflag, 0, ntets);
  double lsum = 0;
  for (size_t t = 0; t < ntets; t++)
    for (int e = 0; e < 6; e++)
      lsum += v3_dist(x_rest + 3 * (size_t)tets[4 * t + TET_SPLIT_EDGE[e][0]],
                      x_rest + 3 * (size_t)tets[4 * t + TET_SPLIT_EDGE[e][1]]);
  c->min_edge = 0.5 * lsum / (6.0 * (double)ntets);
  /* Meshes whose elements are all poorer than 0.1 still cut: the gate is
   * then half the mesh's own worst element. */
  double qmin = INFINITY;
  for (size_t t = 0; t < ntets; t++) qmin = fmin(qmin, tet_cut_quality(c, c->x_rest, t));
  c->min_quality = fmin(0.1, 0.5 * qmin);
  /* Planar projection on the two largest extents: a texture coordinate
   * every node has, so the incision's new vertices carry interpolated ones. */
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < n; i++)
    for (int k = 0; k < 3; k++) {
      lo[k] = fmin(lo[k], x_rest[3 * i + k]);
      hi[k] = fmax(hi[k], x_rest[3 * i + k]);
    }
  int ax[3] = {0, 1, 2};
  for (int a = 0; a < 2; a++)
    for (int b = a + 1; b < 3; b++)
      if (hi[ax[b]] - lo[ax[b]] > hi[ax[a]] - lo[ax[a]]) {
        int t = ax[a];
        ax[a] = ax[b];
        ax[b] = t;
      }
  for (size_t i = 0; i < n; i++)
    for (int k = 0; k < 2; k++) {
      double ext = hi[ax[k]] - lo[ax[k]];
      c->attr[2 * i + k] = ext > 0 ? (x_rest[3 * i + ax[k]] - lo[ax[k]]) / ext : 0;
    }
  if (build_n2t(c)) {
    tet_cut_destroy(c);
    return verr_set(err, "tet_cut: out of memory for the adjacency");
  }
  return 0;
}

void tet_cut_destroy(tet_cut_t *c) {
  if (c->priv) {
    free(c->priv->eh);
    free(c->priv->fh);
    free(c->priv->pend);
    free(c->priv->n2t_start);
    free(c->priv->n2t);
    free(c->priv->spts);
    free(c->priv);
  }
  free(c->x);
  free(c->x_rest);
  free(c->v);
  free(c->attr);
  free(c->fixed);
  free(c->tet);
  free(c->tflag);
  memset(c, 0, sizeof *c);
}

int tet_cut_active(const tet_cut_t *c) { return c->priv && c->priv->active; }

double tet_cut_quality(const tet_cut_t *c, const double *x, size_t i) {
  tet_mesh_t view = {c->n, c->ntets, (double *)x, c->tet};
  return tet_quality(&view, x, i);
}

/* ---- intersection ---------------------------------------------------------- */

/* Edge xi -> xj against triangle (A, B, C): on a hit, the parameter from xi.
 * Nodes within 1e-9 edge lengths of the plane count as on its positive side
 * (the snap rule of the header), so a node on the plane belongs to one side
 * for every edge and triangle alike. */
static int edge_hits_tri(const double *xi, const double *xj, const double *A, const double *B, const double *C,
                         double *t) {
  double ab[3], ac[3], n[3];
  v3_sub(ab, B, A);
  v3_sub(ac, C, A);
  v3_cross(n, ab, ac);
  double nn = v3_norm(n), L = v3_dist(xi, xj);
  if (!(nn > 1e-30) || !(L > 0)) return 0;
  double d[2], e[3];
  v3_sub(e, xi, A);
  d[0] = v3_dot(n, e) / nn;
  v3_sub(e, xj, A);
  d[1] = v3_dot(n, e) / nn;
  for (int k = 0; k < 2; k++)
    if (fabs(d[k]) <= 1e-9 * L) d[k] = 1e-9 * L;
  if ((d[0] > 0) == (d[1] > 0)) return 0;
  double s = d[0] / (d[0] - d[1]);
  double P[3] = {xi[0] + s * (xj[0] - xi[0]), xi[1] + s * (xj[1] - xi[1]), xi[2] + s * (xj[2] - xi[2])};
  /* Inside the triangle, edges included (a small tolerance, so an edge
   * crossing the quad's diagonal is found by one of its triangles). */
  const double *V[3] = {A, B, C};
  for (int k = 0; k < 3; k++) {
    double u[3], w[3], cr[3];
    v3_sub(u, V[(k + 1) % 3], V[k]);
    v3_sub(w, P, V[k]);
    v3_cross(cr, u, w);
    if (v3_dot(cr, n) < -1e-9 * nn * nn) return 0;
  }
  *t = s;
  return 1;
}

/* Does segment a-b (the blade) intersect tetrahedron q at positions x?
 * Clips the segment's parameter range by the four inward half-spaces. */
static int seg_in_tet(const double *x, const uint32_t *q, const double *a, const double *b) {
  double lo = 0, hi = 1;
  for (int f = 0; f < 4 && lo <= hi; f++) {
    const double *p0 = x + 3 * (size_t)q[(f + 1) % 4], *p1 = x + 3 * (size_t)q[(f + 2) % 4],
                 *p2 = x + 3 * (size_t)q[(f + 3) % 4], *opp = x + 3 * (size_t)q[f];
    double u[3], w[3], n[3], e[3];
    v3_sub(u, p1, p0);
    v3_sub(w, p2, p0);
    v3_cross(n, u, w);
    v3_sub(e, opp, p0);
    if (v3_dot(n, e) < 0) v3_scale(n, n, -1);
    v3_sub(e, a, p0);
    double fa = v3_dot(n, e);
    v3_sub(e, b, p0);
    double fb = v3_dot(n, e);
    if (fa < 0 && fb < 0) return 0;
    if (fa < 0) lo = fmax(lo, fa / (fa - fb));
    if (fb < 0) hi = fmin(hi, fa / (fa - fb));
  }
  return lo <= hi;
}

static int add_pending(tet_cut_t *c, uint32_t t) {
  struct tet_cut_priv *p = c->priv;
  if (c->tflag[t] & TC_PENDING) return 0;
  if (p->npend == p->cap_pend) {
    size_t cap = p->cap_pend ? 2 * p->cap_pend : 64;
    if (grow((void **)&p->pend, sizeof(uint32_t), cap)) return -1;
    p->cap_pend = cap;
  }
  p->pend[p->npend++] = t;
  c->tflag[t] |= TC_PENDING;
  return 0;
}

/* Intersects the quad swept from (tip0, handle0) to (tip1, handle1) with
 * the edges of every tetrahedron not created in this cut; new cut edges put
 * every tetrahedron around them in the state table. */
static int sweep(tet_cut_t *c, const double *t0, const double *h0, const double *t1, const double *h1) {
  struct tet_cut_priv *p = c->priv;
  const double *tri[2][3] = {{t0, t1, h1}, {t0, h1, h0}};
  double lo[3], hi[3];
  for (int k = 0; k < 3; k++) {
    lo[k] = fmin(fmin(t0[k], t1[k]), fmin(h0[k], h1[k]));
    hi[k] = fmax(fmax(t0[k], t1[k]), fmax(h0[k], h1[k]));
    double m = 1e-9 * (hi[k] - lo[k] + 1e-12);
    lo[k] -= m;
    hi[k] += m;
  }
  for (size_t t = 0; t < c->ntets; t++) {
    if (c->tflag[t] & TC_FROZEN) continue;
    const uint32_t *q = c->tet + 4 * t;
    int out = 0;
    for (int k = 0; k < 3 && !out; k++) {
      double a = c->x[3 * (size_t)q[0] + k], b = c->x[3 * (size_t)q[1] + k], d = c->x[3 * (size_t)q[2] + k],
             e = c->x[3 * (size_t)q[3] + k];
      if (fmax(fmax(a, b), fmax(d, e)) < lo[k] || fmin(fmin(a, b), fmin(d, e)) > hi[k]) out = 1;
    }
    if (out) continue;
    for (int e = 0; e < 6; e++) {
      uint32_t i = q[TET_SPLIT_EDGE[e][0]], j = q[TET_SPLIT_EDGE[e][1]];
      if (i > j) {
        uint32_t s = i;
        i = j;
        j = s;
      }
      if (edge_find(p, i, j)) continue;
      if (v3_dist(c->x_rest + 3 * (size_t)i, c->x_rest + 3 * (size_t)j) < c->min_edge) continue;
      double s;
      if (!edge_hits_tri(c->x + 3 * (size_t)i, c->x + 3 * (size_t)j, tri[0][0], tri[0][1], tri[0][2], &s) &&
          !edge_hits_tri(c->x + 3 * (size_t)i, c->x + 3 * (size_t)j, tri[1][0], tri[1][1], tri[1][2], &s))
        continue;
      int poor = 0;
      for (uint32_t k = p->n2t_start[i]; k < p->n2t_start[i + 1] && !poor; k++)
        poor = tet_has(c->tet + 4 * (size_t)p->n2t[k], j) && tet_cut_quality(c, c->x_rest, p->n2t[k]) < c->min_quality;
      if (poor) continue;
      eslot_t *sl = edge_insert(p, i, j);
      if (!sl) return -1;
      sl->t = fmin(fmax(s, c->snap), 1 - c->snap);
      c->stats.cut_edges++;
      for (uint32_t k = p->n2t_start[i]; k < p->n2t_start[i + 1]; k++)
        if (tet_has(c->tet + 4 * (size_t)p->n2t[k], j) && add_pending(c, p->n2t[k])) return -1;
    }
  }
  return 0;
}

/* ---- splitting ------------------------------------------------------------- */

static unsigned cut_mask(const tet_cut_t *c, const uint32_t *q) {
  unsigned m = 0;
  for (int e = 0; e < 6; e++)
    if (edge_find(c->priv, q[TET_SPLIT_EDGE[e][0]], q[TET_SPLIT_EDGE[e][1]])) m |= 1u << e;
  return m;
}

/* The point of a cut edge, created on first use (capacity reserved). */
static uint32_t edge_point(tet_cut_t *c, eslot_t *sl) {
  if (sl->node != TC_NONE) return sl->node;
  struct tet_cut_priv *p = c->priv;
  uint32_t i = (uint32_t)(sl->key >> 32), j = (uint32_t)sl->key, k = (uint32_t)c->n++;
  double t = sl->t;
  for (int a = 0; a < 3; a++) {
    c->x[3 * (size_t)k + a] = (1 - t) * c->x[3 * (size_t)i + a] + t * c->x[3 * (size_t)j + a];
    c->x_rest[3 * (size_t)k + a] = (1 - t) * c->x_rest[3 * (size_t)i + a] + t * c->x_rest[3 * (size_t)j + a];
    c->v[3 * (size_t)k + a] = (1 - t) * c->v[3 * (size_t)i + a] + t * c->v[3 * (size_t)j + a];
  }
  for (int a = 0; a < 2; a++)
    c->attr[2 * (size_t)k + a] = (1 - t) * c->attr[2 * (size_t)i + a] + t * c->attr[2 * (size_t)j + a];
  c->fixed[k] = c->fixed[i] && c->fixed[j];
  sl->node = k;
  p->spts[p->nspts++] = (spoint_t){k, i, j};
  return k;
}

/* Splits tetrahedron ti by recursive bisection (see the header); for a
 * general case also remembers the cut faces between its two sides. */
static int split_tet(tet_cut_t *c, uint32_t ti) {
  struct tet_cut_priv *p = c->priv;
  if (reserve(c, 6, TC_MAX_LEAVES)) return -1;
  if (p->nspts + 6 > p->cap_spts) {
    size_t cap = p->cap_spts ? 2 * p->cap_spts : 64;
    while (cap < p->nspts + 6) cap *= 2;
    if (grow((void **)&p->spts, sizeof(spoint_t), cap)) return -1;
    p->cap_spts = cap;
  }
  uint32_t orig[4];
  memcpy(orig, c->tet + 4 * (size_t)ti, sizeof orig);
  int side[4];
  tet_split_case_t cs = tet_split_classify(cut_mask(c, orig), side);
  if (cs == TET_SPLIT_NONE) return 0;
  if (cs == TET_SPLIT_G1 || cs == TET_SPLIT_G2)
    c->stats.split_general[cs - TET_SPLIT_G1]++;
  else
    c->stats.split_partial[cs - TET_SPLIT_P1]++;
  uint32_t stack[TC_MAX_LEAVES], leaves[TC_MAX_LEAVES];
  size_t ns = 0, nl = 0;
  stack[ns++] = ti;
  while (ns) {
    uint32_t t = stack[--ns];
    uint32_t *q = c->tet + 4 * (size_t)t;
    eslot_t *best = NULL;
    for (int e = 0; e < 6; e++) {
      eslot_t *sl = edge_find(p, q[TET_SPLIT_EDGE[e][0]], q[TET_SPLIT_EDGE[e][1]]);
      if (sl && (!best || sl->seq < best->seq)) best = sl;
    }
    if (!best) {
      leaves[nl++] = t;
      continue;
    }
    uint32_t i = (uint32_t)(best->key >> 32), j = (uint32_t)best->key, m = edge_point(c, best);
    uint32_t u = (uint32_t)c->ntets++;
    uint32_t *r = c->tet + 4 * (size_t)u;
    q = c->tet + 4 * (size_t)t; /* unchanged storage: capacity was reserved */
    memcpy(r, q, 4 * sizeof(uint32_t));
    for (int k = 0; k < 4; k++) {
      if (q[k] == j) q[k] = m; /* t keeps i */
      if (r[k] == i) r[k] = m; /* u keeps j */
    }
    c->tflag[t] = (uint8_t)((c->tflag[t] & TC_PENDING) | TC_FROZEN);
    c->tflag[u] = TC_FROZEN;
    stack[ns++] = t;
    stack[ns++] = u;
  }
  for (size_t l = 0; l < nl; l++) c->tflag[leaves[l]] &= (uint8_t)~TC_PENDING;
  if (cs != TET_SPLIT_G1 && cs != TET_SPLIT_G2) return 1;
  /* Side of a leaf: that of any of the parent's nodes it keeps (every leaf
   * keeps one, none keeps nodes of both sides). */
  int lside[TC_MAX_LEAVES];
  for (size_t l = 0; l < nl; l++) {
    lside[l] = -1;
    const uint32_t *q = c->tet + 4 * (size_t)leaves[l];
    for (int k = 0; k < 4 && lside[l] < 0; k++)
      for (int o = 0; o < 4; o++)
        if (q[k] == orig[o]) lside[l] = side[o];
  }
  for (size_t a = 0; a < nl; a++)
    for (size_t b = a + 1; b < nl; b++) {
      if (lside[a] == lside[b]) continue;
      const uint32_t *qa = c->tet + 4 * (size_t)leaves[a], *qb = c->tet + 4 * (size_t)leaves[b];
      uint32_t common[4];
      int nc = 0;
      for (int k = 0; k < 4; k++)
        if (tet_has(qb, qa[k])) common[nc++] = qa[k];
      if (nc == 3 && face_add(p, face_key(common[0], common[1], common[2]))) return -1;
    }
  return 1;
}

/* ---- opening the incision -------------------------------------------------- */

static uint32_t uf_find(uint32_t *par, uint32_t a) {
  while (par[a] != a) a = par[a] = par[par[a]];
  return a;
}

/* Examines the new points whose edge is gone everywhere (see the header). */
static int open_incision(tet_cut_t *c, int final) {
  struct tet_cut_priv *p = c->priv;
  if (build_n2t(c)) return -1;
  size_t keep = 0;
  int changed = 0;
  for (size_t s = 0; s < p->nspts; s++) {
    spoint_t sp = p->spts[s];
    int edge_alive = 0;
    for (uint32_t k = p->n2t_start[sp.i]; k < p->n2t_start[sp.i + 1] && !edge_alive; k++)
      edge_alive = tet_has(c->tet + 4 * (size_t)p->n2t[k], sp.j);
    if (edge_alive && !final) {
      p->spts[keep++] = sp;
      continue;
    }
    if (edge_alive) continue; /* cannot happen after the final splits; never open then */
    uint32_t b0 = p->n2t_start[sp.node], ns = p->n2t_start[sp.node + 1] - b0;
    if (ns < 2) continue;
    uint32_t *par = malloc(ns * sizeof *par);
    if (!par) return -1;
    for (uint32_t a = 0; a < ns; a++) par[a] = a;
    for (uint32_t a = 0; a < ns; a++) {
      const uint32_t *qa = c->tet + 4 * (size_t)p->n2t[b0 + a];
      for (uint32_t b = a + 1; b < ns; b++) {
        const uint32_t *qb = c->tet + 4 * (size_t)p->n2t[b0 + b];
        uint32_t common[4];
        int nc = 0;
        for (int k = 0; k < 4; k++)
          if (tet_has(qb, qa[k])) common[nc++] = qa[k];
        if (nc == 3 && !face_has(p, face_key(common[0], common[1], common[2]))) par[uf_find(par, a)] = uf_find(par, b);
      }
    }
    /* Settle every root first, then give each group but the first its
     * own copy of the point. */
    for (uint32_t a = 0; a < ns; a++) par[a] = uf_find(par, a);
    for (uint32_t a = 1; a < ns; a++) {
      uint32_t root = par[a];
      if (root == par[0] || root != a) continue; /* first group, or not the group's representative */
      if (reserve(c, 1, 0)) {
        free(par);
        return -1;
      }
      uint32_t k = (uint32_t)c->n++;
      memcpy(c->x + 3 * (size_t)k, c->x + 3 * (size_t)sp.node, 3 * sizeof(double));
      memcpy(c->x_rest + 3 * (size_t)k, c->x_rest + 3 * (size_t)sp.node, 3 * sizeof(double));
      memcpy(c->v + 3 * (size_t)k, c->v + 3 * (size_t)sp.node, 3 * sizeof(double));
      memcpy(c->attr + 2 * (size_t)k, c->attr + 2 * (size_t)sp.node, 2 * sizeof(double));
      c->fixed[k] = c->fixed[sp.node];
      c->stats.duplicated++;
      changed = 1;
      for (uint32_t b = 0; b < ns; b++) {
        if (par[b] != root) continue;
        uint32_t *q = c->tet + 4 * (size_t)p->n2t[b0 + b];
        for (int kk = 0; kk < 4; kk++)
          if (q[kk] == sp.node) q[kk] = k;
      }
    }
    free(par);
  }
  p->nspts = keep;
  if (changed && build_n2t(c)) return -1;
  return 0;
}

/* ---- the cut ---------------------------------------------------------------- */

/* Splits the tetrahedra of the state table: all of them when `all`, else
 * the general cases the blade segment (a, b) has left. */
static int split_pending(tet_cut_t *c, int all, const double *a, const double *b) {
  struct tet_cut_priv *p = c->priv;
  int count = 0;
  size_t keep = 0;
  for (size_t k = 0; k < p->npend; k++) {
    uint32_t t = p->pend[k];
    if (!(c->tflag[t] & TC_PENDING)) continue;
    const uint32_t *q = c->tet + 4 * (size_t)t;
    int go = all;
    if (!go) {
      tet_split_case_t cs = tet_split_classify(cut_mask(c, q), NULL);
      go = (cs == TET_SPLIT_G1 || cs == TET_SPLIT_G2) && !seg_in_tet(c->x, q, a, b);
    }
    if (!go) {
      p->pend[keep++] = t;
      continue;
    }
    int rc = split_tet(c, t);
    if (rc < 0) {
      /* Keep the rest in the table: the mesh is consistent (split_tet
       * fails before it changes anything). */
      for (size_t r = k; r < p->npend; r++) p->pend[keep++] = p->pend[r];
      p->npend = keep;
      return -1;
    }
    c->tflag[t] &= (uint8_t)~TC_PENDING;
    count += rc;
  }
  p->npend = keep;
  return count;
}

int tet_cut_advance(tet_cut_t *c, const double tip[3], const double handle[3], verr_t *err) {
  struct tet_cut_priv *p = c->priv;
  if (!p) return verr_set(err, "tet_cut: not created");
  if (!v3_isfinite(tip) || !v3_isfinite(handle)) return verr_set(err, "tet_cut: blade position is not finite");
  if (!p->active) {
    p->active = 1;
    v3_copy(p->tip, tip);
    v3_copy(p->handle, handle);
    return 0;
  }
  double t0 = now_s();
  if (sweep(c, p->tip, p->handle, tip, handle)) return verr_set(err, "tet_cut: out of memory for the edge table");
  double t1 = now_s();
  v3_copy(p->tip, tip);
  v3_copy(p->handle, handle);
  int n = split_pending(c, 0, tip, handle);
  if (n < 0 || (n > 0 && open_incision(c, 0))) {
    c->stats.intersect_s += t1 - t0;
    return verr_set(err, "tet_cut: out of memory splitting (%zu nodes, %zu tetrahedra)", c->n, c->ntets);
  }
  if (n > 0) c->version++;
  c->stats.intersect_s += t1 - t0;
  c->stats.topology_s += now_s() - t1;
  return n;
}

int tet_cut_end(tet_cut_t *c, verr_t *err) {
  struct tet_cut_priv *p = c->priv;
  if (!p) return verr_set(err, "tet_cut: not created");
  double t0 = now_s();
  size_t dup0 = c->stats.duplicated;
  int n = split_pending(c, 1, NULL, NULL);
  if (n < 0 || open_incision(c, 1))
    return verr_set(err, "tet_cut: out of memory splitting (%zu nodes, %zu tetrahedra)", c->n, c->ntets);
  if (n > 0 || c->stats.duplicated != dup0) c->version++;
  /* A new cut starts from a clean table: every point is final. */
  if (p->eh) memset(p->eh, 0, p->eh_cap * sizeof *p->eh);
  if (p->fh) memset(p->fh, 0, p->fh_cap * sizeof *p->fh);
  p->eh_count = p->fh_count = 0;
  p->npend = p->nspts = 0;
  memset(c->tflag, 0, c->ntets);
  p->active = 0;
  c->stats.topology_s += now_s() - t0;
  return n;
}

typedef struct fref {
  uint64_t key;
  uint32_t tet, k;
} fref_t;

static int cmp_fref(const void *a, const void *b) {
  uint64_t x = ((const fref_t *)a)->key, y = ((const fref_t *)b)->key;
  return (x > y) - (x < y);
}

/* Outward faces of a positively oriented tetrahedron (a, b, c, d). */
static const int FACE[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

size_t tet_cut_boundary(const tet_cut_t *c, uint32_t **tris) {
  *tris = NULL;
  size_t nf = 4 * c->ntets;
  fref_t *f = malloc((nf ? nf : 1) * sizeof *f);
  if (!f) return (size_t)-1;
  for (size_t t = 0; t < c->ntets; t++)
    for (uint32_t k = 0; k < 4; k++) {
      const uint32_t *q = c->tet + 4 * t;
      f[4 * t + k] = (fref_t){face_key(q[FACE[k][0]], q[FACE[k][1]], q[FACE[k][2]]), (uint32_t)t, k};
    }
  qsort(f, nf, sizeof *f, cmp_fref);
  size_t count = 0;
  for (size_t a = 0; a < nf;) {
    size_t b = a + 1;
    while (b < nf && f[b].key == f[a].key) b++;
    if (b - a == 1) f[count++] = f[a];
    a = b;
  }
  uint32_t *out = malloc((count ? count : 1) * 3 * sizeof *out);
  if (!out) {
    free(f);
    return (size_t)-1;
  }
  for (size_t s = 0; s < count; s++) {
    const uint32_t *q = c->tet + 4 * (size_t)f[s].tet;
    for (int k = 0; k < 3; k++) out[3 * s + k] = q[FACE[f[s].k][k]];
  }
  free(f);
  *tris = out;
  return count;
}

/* ---- checkpoints ---------------------------------------------------------- */

void tet_cut_save(const tet_cut_t *c, state_blob_t *b) {
  sb_put_u64(b, c->n);
  sb_put_u64(b, c->ntets);
  sb_put(b, c->x_rest, 3 * c->n * sizeof(double));
  sb_put(b, c->attr, 2 * c->n * sizeof(double));
  sb_put(b, c->fixed, c->n);
  sb_put(b, c->tet, 4 * c->ntets * sizeof(uint32_t));
  sb_put(b, c->tflag, c->ntets);
  sb_put_f64(b, c->snap);
  sb_put_f64(b, c->min_edge);
  sb_put_f64(b, c->min_quality);
  sb_put_u64(b, c->version);
  const struct tet_cut_priv *p = c->priv;
  sb_put_u64(b, p->seq);
  sb_put_u64(b, p->eh_count);
  for (size_t s = 0; s < p->eh_cap; s++)
    if (p->eh[s].key) {
      sb_put_u64(b, p->eh[s].key);
      sb_put_u64(b, (uint64_t)p->eh[s].node << 32 | p->eh[s].seq);
      sb_put_f64(b, p->eh[s].t);
    }
  sb_put_u64(b, p->fh_count);
  for (size_t s = 0; s < p->fh_cap; s++)
    if (p->fh[s]) sb_put_u64(b, p->fh[s]);
}

static int load_fail(tet_cut_t *c, void *a, void *f, void *t, verr_t *err, const char *what) {
  free(a);
  free(f);
  free(t);
  if (c->priv || c->x) tet_cut_destroy(c);
  return verr_set(err, "tet_cut: %s", what);
}

int tet_cut_load(tet_cut_t *c, state_blob_t *b, verr_t *err) {
  memset(c, 0, sizeof *c);
  /* Per node at least 41 bytes follow (rest position, attribute, flag),
   * per tetrahedron 17 (indices, flag): counts beyond the bytes left are
   * refused before anything is allocated. */
  size_t n = sb_count(b, 41);
  size_t nt = b->bad ? 0 : (size_t)sb_count(b, 0);
  if (b->bad || nt > (b->len - b->at) / 17 || n == 0 || nt == 0 || n >= TC_MAX_NODES / 2)
    return load_fail(c, NULL, NULL, NULL, err, "bad node or tetrahedron count");
  size_t bytes_x = 3 * n * sizeof(double);
  double *xr = malloc(bytes_x);
  uint8_t *fixed = malloc(n);
  uint32_t *tets = malloc(4 * nt * sizeof *tets);
  if (!xr || !fixed || !tets) return load_fail(c, xr, fixed, tets, err, "out of memory");
  sb_get(b, xr, bytes_x);
  size_t attr_at = b->at;
  b->at += 2 * n * sizeof(double); /* after create, which overwrites attributes */
  sb_get(b, fixed, n);
  sb_get(b, tets, 4 * nt * sizeof *tets);
  if (b->bad) return load_fail(c, xr, fixed, tets, err, "truncated mesh");
  for (size_t i = 0; i < n; i++)
    if (fixed[i] > 1) return load_fail(c, xr, fixed, tets, err, "bad fixed flag");
  verr_t sub;
  if (tet_cut_create(c, n, xr, NULL, NULL, fixed, nt, tets, &sub)) return load_fail(c, xr, fixed, tets, err, sub.msg);
  free(xr);
  free(fixed);
  free(tets);
  memcpy(c->attr, b->p + attr_at, 2 * n * sizeof(double));
  for (size_t k = 0; k < 2 * n; k++)
    if (!isfinite(c->attr[k])) return load_fail(c, NULL, NULL, NULL, err, "non-finite attribute");
  sb_get(b, c->tflag, nt);
  for (size_t t = 0; t < nt; t++) {
    if (c->tflag[t] & ~(TC_PENDING | TC_FROZEN)) return load_fail(c, NULL, NULL, NULL, err, "bad tetrahedron flag");
    c->tflag[t] &= (uint8_t)~TC_PENDING; /* no cut in progress after a restore */
  }
  c->snap = sb_get_f64(b);
  c->min_edge = sb_get_f64(b);
  c->min_quality = sb_get_f64(b);
  uint64_t version = sb_get_u64(b), seq = sb_get_u64(b);
  if (b->bad || !(c->snap > 0 && c->snap < 0.5) || !isfinite(c->min_edge) || !isfinite(c->min_quality) ||
      version > UINT32_MAX || seq > UINT32_MAX)
    return load_fail(c, NULL, NULL, NULL, err, "bad cutter parameters");
  c->version = (uint32_t)version;
  struct tet_cut_priv *p = c->priv;
  size_t ne = sb_count(b, 24);
  for (size_t e = 0; e < ne && !b->bad; e++) {
    uint64_t key = sb_get_u64(b), ns = sb_get_u64(b);
    double t = sb_get_f64(b);
    uint32_t i = (uint32_t)(key >> 32), j = (uint32_t)key, node = (uint32_t)(ns >> 32);
    if (b->bad || i >= j || j >= n || (node != TC_NONE && node >= n) || !(t >= 0 && t <= 1) || edge_find(p, i, j))
      return load_fail(c, NULL, NULL, NULL, err, "bad cut edge");
    eslot_t *sl = edge_insert(p, i, j);
    if (!sl) return load_fail(c, NULL, NULL, NULL, err, "out of memory");
    sl->node = node;
    sl->seq = (uint32_t)ns;
    sl->t = t;
  }
  size_t nf = sb_count(b, 8);
  for (size_t f = 0; f < nf && !b->bad; f++) {
    uint64_t key = sb_get_u64(b);
    if (b->bad || !key || (key >> 42) >= n || ((key >> 21) & (TC_MAX_NODES - 1)) >= n ||
        (key & (TC_MAX_NODES - 1)) >= n || (key >> 63))
      return load_fail(c, NULL, NULL, NULL, err, "bad cut face");
    if (face_add(p, key)) return load_fail(c, NULL, NULL, NULL, err, "out of memory");
  }
  if (b->bad) return load_fail(c, NULL, NULL, NULL, err, "truncated cutter state");
  p->seq = (uint32_t)seq;
  return 0;
}
