/* SPDX-License-Identifier: Apache-2.0 */
#include "tet_embed.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "vmath.h"

int tet_mesh_copy(tet_mesh_t *dst, const tet_mesh_t *src, verr_t *err) {
  memset(dst, 0, sizeof *dst);
  dst->x = malloc(3 * src->nnodes * sizeof *dst->x + 1);
  dst->tets = malloc(4 * src->ntets * sizeof *dst->tets + 1);
  if (!dst->x || !dst->tets) {
    tet_mesh_free(dst);
    return verr_set(err, "out of memory copying %zu tetrahedra", src->ntets);
  }
  memcpy(dst->x, src->x, 3 * src->nnodes * sizeof *dst->x);
  memcpy(dst->tets, src->tets, 4 * src->ntets * sizeof *dst->tets);
  dst->nnodes = src->nnodes;
  dst->ntets = src->ntets;
  return 0;
}

/* ---- boundary ---- */

typedef struct face {
  uint32_t key[3]; /* sorted corners */
  uint32_t tri[3]; /* outward order */
  uint32_t tet;
} face_t;

static int face_cmp(const void *a, const void *b) {
  const face_t *x = a, *y = b;
  for (int k = 0; k < 3; k++)
    if (x->key[k] != y->key[k]) return x->key[k] < y->key[k] ? -1 : 1;
  return 0;
}

static void sort3(uint32_t *k) {
  uint32_t t;
  if (k[0] > k[1]) t = k[0], k[0] = k[1], k[1] = t;
  if (k[1] > k[2]) t = k[1], k[1] = k[2], k[2] = t;
  if (k[0] > k[1]) t = k[0], k[0] = k[1], k[1] = t;
}

int tet_mesh_boundary(const tet_mesh_t *t, mesh_t *surf, uint32_t **node_of_vert, size_t *bad_tet, verr_t *err) {
  /* Outward faces of a positively oriented tetrahedron (0 1 2 3). */
  static const int local[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  memset(surf, 0, sizeof *surf);
  if (node_of_vert) *node_of_vert = NULL;
  size_t nf = 4 * t->ntets;
  face_t *f = malloc(nf * sizeof *f + 1);
  uint32_t *vert_of = malloc(t->nnodes * sizeof *vert_of + 1);
  if (!f || !vert_of) {
    free(f);
    free(vert_of);
    return verr_set(err, "out of memory for the faces of %zu tetrahedra", t->ntets);
  }
  for (size_t i = 0; i < t->ntets; i++)
    for (int q = 0; q < 4; q++) {
      face_t *e = f + 4 * i + q;
      for (int k = 0; k < 3; k++) e->tri[k] = e->key[k] = t->tets[4 * i + (size_t)local[q][k]];
      sort3(e->key);
      e->tet = (uint32_t)i;
    }
  qsort(f, nf, sizeof *f, face_cmp);
  size_t nb = 0;
  int rc = 0;
  for (size_t i = 0; i < nf;) {
    size_t j = i + 1;
    while (j < nf && !face_cmp(f + i, f + j)) j++;
    if (j - i > 2) {
      if (bad_tet) *bad_tet = f[i].tet;
      rc = verr_set(err, "a face (nodes %u %u %u) is shared by %zu tetrahedra (at most 2 in a solid)", f[i].key[0],
                    f[i].key[1], f[i].key[2], j - i);
      break;
    }
    if (j - i == 1) f[nb++] = f[i];
    i = j;
  }
  size_t nv = 0;
  if (!rc) {
    for (size_t i = 0; i < t->nnodes; i++) vert_of[i] = UINT32_MAX;
    for (size_t i = 0; i < nb; i++)
      for (int k = 0; k < 3; k++) vert_of[f[i].tri[k]] = 0;
    for (size_t i = 0; i < t->nnodes; i++)
      if (vert_of[i] == 0) vert_of[i] = (uint32_t)nv++;
    if (!nb) rc = verr_set(err, "the tetrahedra have no boundary faces");
  }
  if (!rc) rc = mesh_alloc(surf, nv, nb, err);
  if (!rc && node_of_vert && !(*node_of_vert = malloc(nv * sizeof **node_of_vert + 1))) {
    mesh_free(surf);
    rc = verr_set(err, "out of memory for %zu boundary vertices", nv);
  }
  if (!rc) {
    for (size_t i = 0; i < t->nnodes; i++) {
      if (vert_of[i] == UINT32_MAX) continue;
      memcpy(surf->pos + 3 * (size_t)vert_of[i], t->x + 3 * i, 3 * sizeof(double));
      if (node_of_vert) (*node_of_vert)[vert_of[i]] = (uint32_t)i;
    }
    for (size_t i = 0; i < nb; i++)
      for (int k = 0; k < 3; k++) surf->tris[3 * i + (size_t)k] = vert_of[f[i].tri[k]];
  }
  free(f);
  free(vert_of);
  return rc;
}

/* ---- embedding ---- */

#define EMBED_MAX_CELLS 2000000
#define EMBED_EPS 1e-9

typedef struct tet_grid {
  double lo[3], h;
  long n[3];
  uint32_t *start, *item; /* cell -> tetrahedra (CSR) */
} tet_grid_t;

static double det4(const double *a, const double *b, const double *c, const double *d) {
  double u[3], v[3], w[3], x[3];
  v3_sub(u, b, a);
  v3_sub(v, c, a);
  v3_sub(w, d, a);
  v3_cross(x, v, w);
  return v3_dot(u, x);
}

static void bary(const tet_mesh_t *t, size_t i, const double *p, double *w) {
  const double *x[4];
  for (int k = 0; k < 4; k++) x[k] = t->x + 3 * (size_t)t->tets[4 * i + (size_t)k];
  double d = det4(x[0], x[1], x[2], x[3]);
  w[1] = det4(x[0], p, x[2], x[3]) / d;
  w[2] = det4(x[0], x[1], p, x[3]) / d;
  w[3] = det4(x[0], x[1], x[2], p) / d;
  w[0] = 1 - w[1] - w[2] - w[3];
}

static double min4(const double *w) { return fmin(fmin(w[0], w[1]), fmin(w[2], w[3])); }

/* Distance from p to tetrahedron i, whose weights for p are w: the nearest
 * point lies on a face whose opposite weight is negative. */
static double dist_to_tet(const tet_mesh_t *t, size_t i, const double *p, const double *w) {
  static const int face[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  if (min4(w) >= 0) return 0;
  double best = INFINITY, cp[3], b[3];
  for (int f = 0; f < 4; f++) {
    if (w[f] >= 0) continue;
    const uint32_t *c = t->tets + 4 * i;
    tri_closest_point(p, t->x + 3 * (size_t)c[face[f][0]], t->x + 3 * (size_t)c[face[f][1]],
                      t->x + 3 * (size_t)c[face[f][2]], cp, b);
    best = fmin(best, v3_dist(cp, p));
  }
  return best;
}

static long cell_coord(const tet_grid_t *g, int k, double v) {
  double f = floor((v - g->lo[k]) / g->h);
  return f < 0 ? 0 : (f >= (double)g->n[k] ? g->n[k] - 1 : (long)f);
}

static size_t cell_index(const tet_grid_t *g, long i, long j, long k) {
  return (size_t)i + (size_t)g->n[0] * ((size_t)j + (size_t)g->n[1] * (size_t)k);
}

static void tet_box(const tet_mesh_t *t, size_t i, double *lo, double *hi) {
  for (int k = 0; k < 3; k++) lo[k] = INFINITY, hi[k] = -INFINITY;
  for (int c = 0; c < 4; c++) {
    const double *x = t->x + 3 * (size_t)t->tets[4 * i + (size_t)c];
    for (int k = 0; k < 3; k++) lo[k] = fmin(lo[k], x[k]), hi[k] = fmax(hi[k], x[k]);
  }
}

static int grid_build(tet_grid_t *g, const tet_mesh_t *t, verr_t *err) {
  double hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int k = 0; k < 3; k++) g->lo[k] = INFINITY;
  for (size_t i = 0; i < t->nnodes; i++)
    for (int k = 0; k < 3; k++) g->lo[k] = fmin(g->lo[k], t->x[3 * i + k]), hi[k] = fmax(hi[k], t->x[3 * i + k]);
  double ext[3], vol = 1, maxe = 0;
  for (int k = 0; k < 3; k++) ext[k] = hi[k] - g->lo[k], maxe = fmax(maxe, ext[k]);
  for (int k = 0; k < 3; k++) vol *= fmax(ext[k], 1e-3 * maxe);
  /* About one tetrahedron per cell, within the cell budget. */
  g->h = fmax(cbrt(vol / (double)(t->ntets ? t->ntets : 1)), cbrt(vol / EMBED_MAX_CELLS));
  if (!(g->h > 0)) return verr_set(err, "the tetrahedral mesh has no extent");
  for (int k = 0; k < 3; k++) g->n[k] = (long)fmin(ceil(ext[k] / g->h), 1e6) + 1;
  size_t nc = (size_t)g->n[0] * (size_t)g->n[1] * (size_t)g->n[2];
  g->start = calloc(nc + 1, sizeof *g->start);
  if (!g->start) return verr_set(err, "out of memory for an embedding grid of %zu cells", nc);
  for (int pass = 0; pass < 2; pass++) {
    for (size_t i = 0; i < t->ntets; i++) {
      double lo[3], up[3];
      tet_box(t, i, lo, up);
      long a[3], b[3];
      for (int k = 0; k < 3; k++) a[k] = cell_coord(g, k, lo[k]), b[k] = cell_coord(g, k, up[k]);
      for (long z = a[2]; z <= b[2]; z++)
        for (long y = a[1]; y <= b[1]; y++)
          for (long x = a[0]; x <= b[0]; x++) {
            size_t c = cell_index(g, x, y, z);
            if (pass == 0)
              g->start[c + 1]++;
            else
              g->item[g->start[c]++] = (uint32_t)i;
          }
    }
    if (pass == 0) {
      for (size_t c = 0; c < nc; c++) g->start[c + 1] += g->start[c];
      g->item = malloc((size_t)g->start[nc] * sizeof *g->item + 1);
      if (!g->item) return verr_set(err, "out of memory for an embedding grid of %u entries", g->start[nc]);
    } else {
      /* The fill advanced each start to the next cell's: shift back. */
      memmove(g->start + 1, g->start, nc * sizeof *g->start);
      g->start[0] = 0;
    }
  }
  return 0;
}

typedef struct best {
  double dist, depth; /* distance to the tetrahedron, its smallest weight */
  uint32_t tet;
  double w[4];
} best_t;

static void consider(const tet_mesh_t *t, const tet_grid_t *g, size_t c, const double *p, best_t *b) {
  for (uint32_t q = g->start[c]; q < g->start[c + 1]; q++) {
    uint32_t i = g->item[q];
    double w[4];
    bary(t, i, p, w);
    double depth = min4(w);
    double d = depth >= -EMBED_EPS ? 0 : dist_to_tet(t, i, p, w);
    if (d < b->dist || (d == b->dist && depth > b->depth)) {
      b->dist = d;
      b->depth = depth;
      b->tet = i;
      memcpy(b->w, w, sizeof w);
    }
  }
}

/* Visits the cells at Chebyshev distance r from c; 0 when none exists. */
static int ring(const tet_mesh_t *t, const tet_grid_t *g, const long *c, long r, const double *p, best_t *b) {
  int any = 0;
  for (long z = c[2] - r; z <= c[2] + r; z++)
    for (long y = c[1] - r; y <= c[1] + r; y++)
      for (long x = c[0] - r; x <= c[0] + r; x++) {
        if (labs(x - c[0]) != r && labs(y - c[1]) != r && labs(z - c[2]) != r) continue;
        if (x < 0 || y < 0 || z < 0 || x >= g->n[0] || y >= g->n[1] || z >= g->n[2]) continue;
        any = 1;
        consider(t, g, cell_index(g, x, y, z), p, b);
      }
  return any;
}

int tet_embed_points(const tet_mesh_t *t, const double *p, size_t n, tet_embedding_t *emb, tet_embed_report_t *rep,
                     verr_t *err) {
  memset(emb, 0, sizeof *emb);
  if (rep) memset(rep, 0, sizeof *rep);
  if (!t->ntets) return verr_set(err, "no tetrahedra to embed in");
  tet_grid_t g;
  memset(&g, 0, sizeof g);
  emb->tet = malloc(n * sizeof *emb->tet + 1);
  emb->bary = malloc(4 * n * sizeof *emb->bary + 1);
  int rc = !emb->tet || !emb->bary ? verr_set(err, "out of memory embedding %zu points", n) : grid_build(&g, t, err);
  if (rc) {
    tet_embedding_free(emb);
    free(g.start);
    free(g.item);
    return -1;
  }
  emb->nsurf = n;
  for (size_t v = 0; v < n; v++) {
    const double *q = p + 3 * v;
    long c[3];
    for (int k = 0; k < 3; k++) c[k] = cell_coord(&g, k, q[k]);
    best_t b = {INFINITY, -INFINITY, 0, {0, 0, 0, 0}};
    /* A tetrahedron sits in every cell its box touches, so one at distance d
     * from q is found by ring ceil(d / h) + 1 at the latest. */
    for (long r = 0;; r++) {
      if (!ring(t, &g, c, r, q, &b) && r > 0 && b.dist < INFINITY) break;
      if (b.dist <= (double)(r - 1) * g.h) break;
      if (r > g.n[0] + g.n[1] + g.n[2]) break;
    }
    emb->tet[v] = b.tet;
    memcpy(emb->bary + 4 * v, b.w, sizeof b.w);
    if (rep && b.dist > 0) {
      rep->outside++;
      rep->max_distance = fmax(rep->max_distance, b.dist);
    }
  }
  free(g.start);
  free(g.item);
  return 0;
}
