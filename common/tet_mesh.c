/* SPDX-License-Identifier: Apache-2.0 */
/* tet_mesh: regular-grid tetrahedral meshes and the surface embedding.
 * See tet_mesh.h for the contract. */
#include "tet_mesh.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "vmath.h"
#include "vtime.h"

/* ---- the 5-tetrahedron cell split -------------------------------------- */

/* Corners of a cell are numbered by bits: corner b sits at (b&1, b>>1&1, b>>2&1).
 * Split A keeps a central tetrahedron on the corners with an odd number of bits
 * (1, 2, 4, 7) and cuts off the four even corners; split B is its mirror. Every
 * face diagonal is an edge of the central tetrahedron, so split A draws the
 * diagonals between odd corners and split B between even ones. Using A in cells
 * whose origin has an even index sum and B in the others makes every diagonal join
 * two nodes of odd global parity: the two cells sharing a face cut it along the
 * same diagonal, so neighbouring faces match and there are no T-cracks. */
static const unsigned char cell_split[2][5][4] = {
    {{1, 2, 4, 7}, {0, 1, 2, 4}, {3, 1, 2, 7}, {5, 1, 4, 7}, {6, 2, 4, 7}},
    {{0, 3, 5, 6}, {1, 0, 3, 5}, {2, 0, 3, 6}, {4, 0, 5, 6}, {7, 3, 5, 6}},
};

/* Signed 6x volume of (a, b, c, d): det[b-a, c-a, d-a]. */
static double det6(const double *a, const double *b, const double *c, const double *d) {
  double e1[3], e2[3], e3[3], n[3];
  v3_sub(e1, b, a);
  v3_sub(e2, c, a);
  v3_sub(e3, d, a);
  v3_cross(n, e2, e3);
  return v3_dot(e1, n);
}

/* Writes the 5 tetrahedra of a cell whose 8 corner node ids are `corner`,
 * swapping two vertices where needed so every one is positively oriented (the
 * mirrored split and the corner tetrahedra come out with either sign). */
static void emit_cell(const uint32_t corner[8], int parity, const double *x, uint32_t *out) {
  for (int t = 0; t < 5; t++) {
    uint32_t *q = out + 4 * t;
    for (int k = 0; k < 4; k++) q[k] = corner[cell_split[parity][t][k]];
    if (det6(x + 3 * (size_t)q[0], x + 3 * (size_t)q[1], x + 3 * (size_t)q[2], x + 3 * (size_t)q[3]) < 0) {
      uint32_t s = q[2];
      q[2] = q[3];
      q[3] = s;
    }
  }
}

void tet_mesh_free(tet_mesh_t *t) {
  if (!t) return;
  free(t->x);
  free(t->tets);
  memset(t, 0, sizeof *t);
}

void tet_embedding_free(tet_embedding_t *e) {
  if (!e) return;
  free(e->tet);
  free(e->bary);
  memset(e, 0, sizeof *e);
}

int tet_mesh_box_grid(size_t nx, size_t ny, size_t nz, double h, tet_mesh_t *out, verr_t *err) {
  memset(out, 0, sizeof *out);
  if (nx < 2 || ny < 2 || nz < 2)
    return verr_set(err, "tet_mesh_box_grid: need at least 2 nodes per axis, got %zu x %zu x %zu", nx, ny, nz);
  if (!(h > 0) || !isfinite(h))
    return verr_set(err, "tet_mesh_box_grid: spacing h must be positive and finite, got %g", h);
  /* Node ids are uint32: refuse grids whose ids or tetrahedron count overflow. */
  if (nx > UINT32_MAX / ny || nx * ny > UINT32_MAX / nz)
    return verr_set(err, "tet_mesh_box_grid: %zu x %zu x %zu nodes overflow 32-bit ids", nx, ny, nz);
  size_t nn = nx * ny * nz, ncell = (nx - 1) * (ny - 1) * (nz - 1);
  if (ncell > SIZE_MAX / 20) return verr_set(err, "tet_mesh_box_grid: too many cells");
  out->x = malloc(3 * nn * sizeof *out->x);
  out->tets = malloc(20 * ncell * sizeof *out->tets);
  if (!out->x || !out->tets) {
    tet_mesh_free(out);
    return verr_set(err, "tet_mesh_box_grid: out of memory for %zu nodes", nn);
  }
  out->nnodes = nn;
  out->ntets = 5 * ncell;
  for (size_t k = 0; k < nz; k++)
    for (size_t j = 0; j < ny; j++)
      for (size_t i = 0; i < nx; i++)
        v3_set(out->x + 3 * (i + nx * (j + ny * k)), (double)i * h, (double)j * h, (double)k * h);
  size_t c = 0;
  for (size_t k = 0; k + 1 < nz; k++)
    for (size_t j = 0; j + 1 < ny; j++)
      for (size_t i = 0; i + 1 < nx; i++, c++) {
        uint32_t corner[8];
        for (int b = 0; b < 8; b++)
          corner[b] = (uint32_t)((i + (b & 1)) + nx * ((j + (b >> 1 & 1)) + ny * (k + (b >> 2 & 1))));
        emit_cell(corner, (int)((i + j + k) & 1), out->x, out->tets + 20 * c);
      }
  return 0;
}

/* ---- per-tetrahedron measures ------------------------------------------- */

double tet_volume(const tet_mesh_t *t, const double *x, size_t i) {
  const uint32_t *q = t->tets + 4 * i;
  return det6(x + 3 * (size_t)q[0], x + 3 * (size_t)q[1], x + 3 * (size_t)q[2], x + 3 * (size_t)q[3]) / 6.0;
}

/* Radius ratio 3 r_in / r_circ with r_in = 3 V / (sum of face areas) and the
 * circumcentre offset from x0 equal to (|a|^2 b x c + |b|^2 c x a + |c|^2 a x b) / (12 V)
 * for edges a, b, c from x0. An inverted or flat tetrahedron scores 0: for the
 * solvers it is as useless as a flat one, and [0, 1] keeps comparisons simple. */
static double quality4(const double *p0, const double *p1, const double *p2, const double *p3) {
  double a[3], b[3], c[3], bc[3], ca[3], ab[3], r[3];
  v3_sub(a, p1, p0);
  v3_sub(b, p2, p0);
  v3_sub(c, p3, p0);
  v3_cross(bc, b, c);
  v3_cross(ca, c, a);
  v3_cross(ab, a, b);
  double v6 = v3_dot(a, bc);
  if (!(v6 > 0)) return 0;
  /* Face areas x2: the three faces at p0 and the opposite one. */
  double d1[3], d2[3], n4[3];
  v3_sub(d1, p2, p1);
  v3_sub(d2, p3, p1);
  v3_cross(n4, d1, d2);
  double area2 = v3_norm(bc) + v3_norm(ca) + v3_norm(ab) + v3_norm(n4);
  v3_scale(r, bc, v3_dot(a, a));
  v3_axpy(r, ca, v3_dot(b, b));
  v3_axpy(r, ab, v3_dot(c, c));
  double rcirc = v3_norm(r) / (2 * v6); /* 12 V = 2 * 6V */
  double rin = v6 / area2;              /* 3 V / A = 6V / (2A) */
  if (!(rcirc > 0) || !isfinite(rcirc)) return 0;
  double q = 3 * rin / rcirc;
  return q > 1 ? 1 : (q > 0 ? q : 0);
}

double tet_quality(const tet_mesh_t *t, const double *x, size_t i) {
  const uint32_t *q = t->tets + 4 * i;
  return quality4(x + 3 * (size_t)q[0], x + 3 * (size_t)q[1], x + 3 * (size_t)q[2], x + 3 * (size_t)q[3]);
}

void tet_embedding_apply(const tet_embedding_t *e, const tet_mesh_t *t, const double *x_nodes, double *surf_x) {
  for (size_t v = 0; v < e->nsurf; v++) {
    const uint32_t *q = t->tets + 4 * (size_t)e->tet[v];
    const double *w = e->bary + 4 * v;
    double *o = surf_x + 3 * v;
    for (int k = 0; k < 3; k++)
      o[k] = w[0] * x_nodes[3 * (size_t)q[0] + k] + w[1] * x_nodes[3 * (size_t)q[1] + k] +
             w[2] * x_nodes[3 * (size_t)q[2] + k] + w[3] * x_nodes[3 * (size_t)q[3] + k];
  }
}

/* ---- building from a surface -------------------------------------------- */

/* The solvers run at interactive rates, so meshes above TET_MAX_TETS are refused
 * (automatic sizing coarsens to stay below); TET_MAX_GRID_CELLS bounds the
 * classification work and memory before anything is evaluated. */
#define TET_MAX_TETS 200000
#define TET_MIN_TETS 1000
#define TET_AUTO_CELLS_ACROSS 8.0
#define TET_MAX_GRID_CELLS ((size_t)4 << 20)
#define TET_MAX_CELLS_PER_AXIS 512.0
/* A boundary node moves towards the surface only if every tetrahedron around it
 * keeps at least this radius ratio: the grid's own are 0.73 and 1. */
#define TET_SNAP_MIN_QUALITY 0.25
/* A tree cluster is replaced by its dipole when the query point is farther than
 * WN_BETA times the cluster's radius. The first-order error this leaves is far
 * below the 1/2 threshold: 2.0 and 2.5 classify every organ here identically,
 * and 2.0 is a third faster. */
#define WN_BETA 2.0
#define BVH_LEAF 4
/* Median splits keep the depth at log2(triangles / BVH_LEAF) + 1 <= 32, and a
 * depth-first walk holds at most depth + 1 entries. */
#define BVH_STACK 128
/* A vertex is inside a tetrahedron when no barycentric weight is below -EMBED_EPS. */
#define EMBED_EPS 1e-10
/* M_PI is POSIX, not C11. */
#define TET_PI 3.14159265358979323846

typedef struct bvh_node {
  double lo[3], hi[3]; /* bounds of the triangles' vertices */
  double n[3];         /* sum of the triangles' area vectors (area times unit normal) */
  double c[3], r;      /* bounding ball of the cluster, for the far-field test */
  uint32_t first;      /* leaf: first slot in order; inner: left child (right is first + 1) */
  uint32_t count;      /* leaf: number of triangles; inner: 0 */
} bvh_node_t;

/* The surface, moved so its bounding box is centred on the origin (far-away
 * meshes would otherwise lose digits in every difference), with its tree. */
typedef struct surf {
  size_t ntris;
  const uint32_t *tris;
  double *p; /* 3 nverts, local coordinates */
  uint32_t *order;
  bvh_node_t *nodes;
  size_t nnodes;
} surf_t;

static void surf_free(surf_t *s) {
  free(s->p);
  free(s->order);
  free(s->nodes);
}

static const double *tri_v(const surf_t *s, uint32_t t, int k) { return s->p + 3 * (size_t)s->tris[3 * (size_t)t + k]; }

/* Moves the k-th smallest (by key[3 i + axis]) of idx[0..n) to slot k, smaller
 * ones before it, larger after (Hoare partition): a median split keeps the tree
 * depth at log2(n) whatever the triangle distribution. */
static void select_kth(uint32_t *idx, long n, long k, const double *key, int axis) {
  long lo = 0, hi = n - 1;
  while (lo < hi) {
    double pivot = key[3 * (size_t)idx[(lo + hi) / 2] + axis];
    long i = lo, j = hi;
    while (i <= j) {
      while (key[3 * (size_t)idx[i] + axis] < pivot) i++;
      while (key[3 * (size_t)idx[j] + axis] > pivot) j--;
      if (i <= j) {
        uint32_t t = idx[i];
        idx[i++] = idx[j];
        idx[j--] = t;
      }
    }
    if (k <= j)
      hi = j;
    else if (k >= i)
      lo = i;
    else
      return;
  }
}

static void bvh_build_node(surf_t *s, const double *cen, uint32_t ni, uint32_t begin, uint32_t end) {
  bvh_node_t *nd = s->nodes + ni;
  for (int k = 0; k < 3; k++) nd->lo[k] = INFINITY, nd->hi[k] = -INFINITY, nd->n[k] = 0;
  double clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (uint32_t i = begin; i < end; i++) {
    uint32_t t = s->order[i];
    const double *a = tri_v(s, t, 0), *b = tri_v(s, t, 1), *c = tri_v(s, t, 2);
    for (int k = 0; k < 3; k++) {
      nd->lo[k] = fmin(nd->lo[k], fmin(a[k], fmin(b[k], c[k])));
      nd->hi[k] = fmax(nd->hi[k], fmax(a[k], fmax(b[k], c[k])));
      clo[k] = fmin(clo[k], cen[3 * (size_t)t + k]);
      chi[k] = fmax(chi[k], cen[3 * (size_t)t + k]);
    }
    double e1[3], e2[3], an[3];
    v3_sub(e1, b, a);
    v3_sub(e2, c, a);
    v3_cross(an, e1, e2);
    v3_axpy(nd->n, an, 0.5);
  }
  /* The box centre and half diagonal: a ball holding every triangle. */
  double d[3];
  for (int k = 0; k < 3; k++) nd->c[k] = 0.5 * (nd->lo[k] + nd->hi[k]), d[k] = nd->hi[k] - nd->lo[k];
  nd->r = 0.5 * v3_norm(d);
  if (end - begin <= BVH_LEAF) {
    nd->first = begin;
    nd->count = end - begin;
    return;
  }
  int axis = 0;
  for (int k = 1; k < 3; k++)
    if (chi[k] - clo[k] > chi[axis] - clo[axis]) axis = k;
  uint32_t mid = begin + (end - begin) / 2;
  select_kth(s->order + begin, (long)(end - begin), (long)(mid - begin), cen, axis);
  uint32_t left = (uint32_t)s->nnodes;
  s->nnodes += 2;
  nd->first = left;
  nd->count = 0;
  bvh_build_node(s, cen, left, begin, mid);
  bvh_build_node(s, cen, left + 1, mid, end);
}

/* Copies the surface into local coordinates (minus `centre`) and builds the tree. */
static int surf_init(surf_t *s, const mesh_t *m, const double *centre, verr_t *err) {
  memset(s, 0, sizeof *s);
  s->ntris = m->ntris;
  s->tris = m->tris;
  s->p = malloc(3 * m->nverts * sizeof *s->p);
  s->order = malloc(m->ntris * sizeof *s->order);
  s->nodes = malloc(2 * m->ntris * sizeof *s->nodes);
  double *cen = malloc(3 * m->ntris * sizeof *cen);
  if (!s->p || !s->order || !s->nodes || !cen) {
    free(cen);
    surf_free(s);
    return verr_set(err, "tet_mesh_build: out of memory for a surface of %zu triangles", m->ntris);
  }
  for (size_t v = 0; v < m->nverts; v++) v3_sub(s->p + 3 * v, m->pos + 3 * v, centre);
  for (size_t t = 0; t < m->ntris; t++) {
    s->order[t] = (uint32_t)t;
    double *c = cen + 3 * t;
    v3_add(c, tri_v(s, (uint32_t)t, 0), tri_v(s, (uint32_t)t, 1));
    v3_add(c, c, tri_v(s, (uint32_t)t, 2));
    v3_scale(c, c, 1.0 / 3.0);
  }
  s->nnodes = 1;
  bvh_build_node(s, cen, 0, 0, (uint32_t)m->ntris);
  free(cen);
  return 0;
}

/* Generalized winding number of the surface at q: the summed solid angle over
 * 4 pi. 1 inside a closed outward surface, 0 outside, and it degrades gently
 * where the surface has holes, which is why it decides inside here rather than
 * ray parity. Far clusters count as dipoles (their summed area vector at their
 * centre), so a query costs about log(triangles) instead of all of them. */
static double winding_number(const surf_t *s, const double *q) {
  uint32_t stack[BVH_STACK];
  int sp = 0;
  stack[sp++] = 0;
  double omega = 0;
  while (sp) {
    const bvh_node_t *nd = s->nodes + stack[--sp];
    double d[3];
    v3_sub(d, nd->c, q);
    double dist = v3_norm(d);
    if (dist > WN_BETA * nd->r) {
      omega += v3_dot(nd->n, d) / (dist * dist * dist);
    } else if (nd->count) {
      for (uint32_t i = 0; i < nd->count; i++) {
        uint32_t t = s->order[nd->first + i];
        omega += tri_solid_angle(q, tri_v(s, t, 0), tri_v(s, t, 1), tri_v(s, t, 2));
      }
    } else {
      stack[sp++] = nd->first;
      stack[sp++] = nd->first + 1;
    }
  }
  return omega / (4 * TET_PI);
}

static double box_dist2(const bvh_node_t *nd, const double *q) {
  double d2 = 0;
  for (int k = 0; k < 3; k++) {
    double e = q[k] < nd->lo[k] ? nd->lo[k] - q[k] : (q[k] > nd->hi[k] ? q[k] - nd->hi[k] : 0);
    d2 += e * e;
  }
  return d2;
}

/* Closest point of the surface to q (branch and bound over the tree). */
static void closest_point(const surf_t *s, const double *q, double *out) {
  uint32_t stack[BVH_STACK];
  int sp = 0;
  stack[sp++] = 0;
  double best = INFINITY;
  v3_copy(out, q);
  while (sp) {
    const bvh_node_t *nd = s->nodes + stack[--sp];
    if (box_dist2(nd, q) >= best) continue;
    if (nd->count) {
      for (uint32_t i = 0; i < nd->count; i++) {
        uint32_t t = s->order[nd->first + i];
        double cp[3], bary[3];
        tri_closest_point(q, tri_v(s, t, 0), tri_v(s, t, 1), tri_v(s, t, 2), cp, bary);
        double d2 = (cp[0] - q[0]) * (cp[0] - q[0]) + (cp[1] - q[1]) * (cp[1] - q[1]) + (cp[2] - q[2]) * (cp[2] - q[2]);
        if (d2 < best) best = d2, v3_copy(out, cp);
      }
    } else {
      /* Nearer child last, so it is searched first and prunes the other. */
      uint32_t a = nd->first, b = nd->first + 1;
      if (box_dist2(s->nodes + a, q) < box_dist2(s->nodes + b, q)) a = b, b = nd->first;
      stack[sp++] = a;
      stack[sp++] = b;
    }
  }
}

/* The cell grid, in local coordinates. Its origin is shifted by a small odd
 * fraction of a cell so that cell centres do not fall exactly on the planes and
 * symmetry axes that generated meshes are made of: the winding number is
 * undefined on the surface itself. */
typedef struct grid {
  double origin[3], h;
  size_t n[3]; /* cells per axis; nodes are n + 1 */
} grid_t;

static const double grid_jitter[3] = {0.0137, 0.0071, 0.0103};

/* Number of cells a grid of spacing h needs over extents `ext`, as a double so
 * absurd sizes do not overflow. */
static double grid_cells_for(const double *ext, double h) {
  double c = 1;
  for (int k = 0; k < 3; k++) c *= ceil(ext[k] / h) + 1;
  return c;
}

static void grid_make(grid_t *g, const double *ext, double h) {
  g->h = h;
  for (int k = 0; k < 3; k++) {
    /* One extra cell leaves half a cell of margin each side of the bounds. */
    g->n[k] = (size_t)ceil(ext[k] / h) + 1;
    g->origin[k] = -0.5 * (double)g->n[k] * h + grid_jitter[k] * h;
  }
}

static size_t grid_ncells(const grid_t *g) { return g->n[0] * g->n[1] * g->n[2]; }

static void cell_centre(const grid_t *g, size_t i, size_t j, size_t k, double *q) {
  q[0] = g->origin[0] + ((double)i + 0.5) * g->h;
  q[1] = g->origin[1] + ((double)j + 0.5) * g->h;
  q[2] = g->origin[2] + ((double)k + 0.5) * g->h;
}

/* Marks the cells whose centre has |winding number| >= 1/2; returns how many.
 * The absolute value accepts a surface whose triangles all face inwards. */
static size_t classify(const surf_t *s, const grid_t *g, unsigned char *keep) {
  size_t nin = 0, c = 0;
  for (size_t k = 0; k < g->n[2]; k++)
    for (size_t j = 0; j < g->n[1]; j++)
      for (size_t i = 0; i < g->n[0]; i++, c++) {
        double q[3];
        cell_centre(g, i, j, k, q);
        keep[c] = fabs(winding_number(s, q)) >= 0.5;
        nin += keep[c];
      }
  return nin;
}

/* Barycentric weights of p in tetrahedron (x0..x3); w0 = 1 - the others so
 * they sum to one, which is what reproduces p at rest. */
static void barycentric(const double *x0, const double *x1, const double *x2, const double *x3, const double *p,
                        double *w) {
  double d = det6(x0, x1, x2, x3);
  w[1] = det6(x0, p, x2, x3) / d;
  w[2] = det6(x0, x1, p, x3) / d;
  w[3] = det6(x0, x1, x2, p) / d;
  w[0] = 1 - w[1] - w[2] - w[3];
}

static double min4(const double *w) { return fmin(fmin(w[0], w[1]), fmin(w[2], w[3])); }

/* Distance from p to tetrahedron (x0..x3) whose weights for p are w. The
 * nearest point lies on a face p is in front of, one whose opposite weight is
 * negative, so only those are measured. */
static double tet_point_dist(const double *const x[4], const double *p, const double *w) {
  if (min4(w) >= 0) return 0;
  static const int face[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  double best = INFINITY;
  for (int f = 0; f < 3; f++) {
    if (w[f] >= 0) continue;
    double cp[3], bary[3];
    tri_closest_point(p, x[face[f][0]], x[face[f][1]], x[face[f][2]], cp, bary);
    best = fmin(best, v3_dist(cp, p));
  }
  return best;
}

typedef struct build {
  grid_t g;
  unsigned char *keep;       /* per cell */
  uint32_t *cell_tet;        /* per cell: its first tetrahedron, or UINT32_MAX */
  uint32_t *node_of;         /* per grid node: mesh node, or UINT32_MAX */
  uint32_t *inc_start, *inc; /* node -> tetrahedra (CSR) */
} build_t;

static void build_free(build_t *b) {
  free(b->keep);
  free(b->cell_tet);
  free(b->node_of);
  free(b->inc_start);
  free(b->inc);
}

static size_t gnode(const grid_t *g, size_t i, size_t j, size_t k) {
  return i + (g->n[0] + 1) * (j + (g->n[1] + 1) * k);
}

/* Moves boundary nodes towards their closest surface point: the grid's staircase
 * otherwise loses or adds up to half a cell of material all round. A move is
 * tried whole, then half, then a quarter, and kept only if every tetrahedron
 * around the node stays positive with quality >= TET_SNAP_MIN_QUALITY, so
 * snapping never inverts or flattens anything. The first pass moves only nodes
 * inside the surface (outwards): a boundary tetrahedron joining an inside and an
 * outside node is flattened by whichever moves first, and letting the outside
 * ones go first cost 3-4 % of the volume on a coarse sphere, against 1 % this
 * way. Later passes move everyone, including nodes blocked before. Moves stay
 * within one cell of the grid position (a farther surface point belongs to
 * another part of the organ), which the embedding's neighbourhood search relies on. */
static void snap_boundary(const surf_t *s, const build_t *b, tet_mesh_t *t, const unsigned char *boundary,
                          const double *x_grid) {
  static const double frac[3] = {1.0, 0.5, 0.25};
  for (int pass = 0; pass < 3; pass++)
    for (size_t v = 0; v < t->nnodes; v++) {
      if (!boundary[v]) continue;
      if (pass == 0 && fabs(winding_number(s, x_grid + 3 * v)) < 0.5) continue;
      double *x = t->x + 3 * v, orig[3], cp[3], d[3], moved[3];
      v3_copy(orig, x);
      closest_point(s, x_grid + 3 * v, cp);
      v3_sub(d, cp, x);
      v3_sub(moved, cp, x_grid + 3 * v);
      if (v3_norm(moved) > b->g.h || v3_norm(d) == 0) continue;
      for (int f = 0; f < 3; f++) {
        v3_copy(x, orig);
        v3_axpy(x, d, frac[f]);
        int ok = 1;
        for (uint32_t i = b->inc_start[v]; ok && i < b->inc_start[v + 1]; i++)
          ok = tet_quality(t, t->x, b->inc[i]) >= TET_SNAP_MIN_QUALITY;
        if (ok) break;
        v3_copy(x, orig);
      }
    }
}

/* The best tetrahedron seen so far in a search around a surface vertex. */
typedef struct best_tet {
  double score; /* containment: min weight (higher better); nearest: -distance */
  uint32_t tet;
  double w[4];
} best_tet_t;

static void consider_cell(const build_t *b, const tet_mesh_t *t, size_t ci, size_t cj, size_t ck, const double *p,
                          int nearest, best_tet_t *best) {
  const grid_t *g = &b->g;
  size_t cell = ci + g->n[0] * (cj + g->n[1] * ck);
  if (b->cell_tet[cell] == UINT32_MAX) return;
  if (nearest) {
    /* The cell's tetrahedra lie within its box grown by h (the snapping limit):
     * skip the cell when that box is already farther than the best found. */
    double d2 = 0;
    size_t idx[3] = {ci, cj, ck};
    for (int k = 0; k < 3; k++) {
      double lo = g->origin[k] + ((double)idx[k] - 1) * g->h, hi = g->origin[k] + ((double)idx[k] + 2) * g->h;
      double e = p[k] < lo ? lo - p[k] : (p[k] > hi ? p[k] - hi : 0);
      d2 += e * e;
    }
    if (best->score > -INFINITY && d2 >= best->score * best->score) return;
  }
  for (uint32_t i = b->cell_tet[cell]; i < b->cell_tet[cell] + 5; i++) {
    const uint32_t *q = t->tets + 4 * (size_t)i;
    const double *x[4] = {t->x + 3 * (size_t)q[0], t->x + 3 * (size_t)q[1], t->x + 3 * (size_t)q[2],
                          t->x + 3 * (size_t)q[3]};
    double w[4];
    barycentric(x[0], x[1], x[2], x[3], p, w);
    double score = nearest ? -tet_point_dist(x, p, w) : min4(w);
    if (score > best->score) {
      best->score = score;
      best->tet = i;
      memcpy(best->w, w, sizeof w);
    }
  }
}

/* Offers the tetrahedra of the kept cells at Chebyshev distance r from cell c
 * to `best`. Returns 0 when the ring lies entirely outside the grid (the search
 * can stop). */
static int visit_ring(const build_t *b, const tet_mesh_t *t, const long *c, long r, const double *p, int nearest,
                      best_tet_t *best) {
  const grid_t *g = &b->g;
  int any = 0;
  for (long k = c[2] - r; k <= c[2] + r; k++) {
    if (k < 0 || k >= (long)g->n[2]) continue;
    for (long j = c[1] - r; j <= c[1] + r; j++) {
      if (j < 0 || j >= (long)g->n[1]) continue;
      int edge_jk = labs(k - c[2]) == r || labs(j - c[1]) == r;
      /* Inside the ring's shell only the two end cells of an x row belong to it. */
      for (long i = c[0] - r; i <= c[0] + r; i += (edge_jk || r == 0) ? 1 : 2 * r) {
        if (i < 0 || i >= (long)g->n[0]) continue;
        any = 1;
        consider_cell(b, t, (size_t)i, (size_t)j, (size_t)k, p, nearest, best);
      }
    }
  }
  return any;
}

/* Embeds surface vertex p (local coordinates): the tetrahedron holding it, found
 * among the cells next to p's cell (snapping moves nodes by at most a cell, so
 * no other cell's tetrahedra can reach p); otherwise the nearest tetrahedron,
 * searched ring by ring until no farther ring can hold a nearer one. Returns 1
 * when the nearest one had to be used. */
static int embed_vertex(const build_t *b, const tet_mesh_t *t, const double *p, uint32_t *tet, double *w) {
  const grid_t *g = &b->g;
  long c[3];
  for (int k = 0; k < 3; k++) {
    double f = floor((p[k] - g->origin[k]) / g->h);
    c[k] = f < 0 ? 0 : (f >= (double)g->n[k] ? (long)g->n[k] - 1 : (long)f);
  }
  best_tet_t best = {-INFINITY, 0, {0, 0, 0, 0}};
  visit_ring(b, t, c, 0, p, 0, &best);
  visit_ring(b, t, c, 1, p, 0, &best);
  if (best.score >= -EMBED_EPS) {
    *tet = best.tet;
    memcpy(w, best.w, sizeof best.w);
    return 0;
  }
  /* A tetrahedron in ring r is at least (r - 2) h away: its cell is r - 1 cells
   * beyond p's, and snapping moved its nodes by at most h. */
  best = (best_tet_t){-INFINITY, 0, {0, 0, 0, 0}};
  for (long r = 0;; r++) {
    if (!visit_ring(b, t, c, r, p, 1, &best)) break;
    if (best.score > -INFINITY && -best.score <= (double)(r - 1) * g->h) break;
  }
  *tet = best.tet;
  memcpy(w, best.w, sizeof best.w);
  return 1;
}

static double surface_volume_local(const surf_t *s) {
  double v = 0;
  for (size_t t = 0; t < s->ntris; t++) {
    double c[3];
    v3_cross(c, tri_v(s, (uint32_t)t, 1), tri_v(s, (uint32_t)t, 2));
    v += v3_dot(tri_v(s, (uint32_t)t, 0), c);
  }
  return v / 6.0;
}

/* Picks the spacing and classifies the grid: returns the number of kept cells,
 * 0 with err set on failure. */
static size_t choose_grid(const surf_t *s, const double *ext, double target_edge, double surf_vol, build_t *b,
                          verr_t *err) {
  double maxe = fmax(ext[0], fmax(ext[1], ext[2])), mine = fmin(ext[0], fmin(ext[1], ext[2]));
  int automatic = !(target_edge > 0);
  double h = target_edge;
  if (automatic) {
    h = mine / TET_AUTO_CELLS_ACROSS;
    /* A flat or needle-thin surface would ask for a grid without end. */
    h = fmax(h, maxe / TET_MAX_CELLS_PER_AXIS);
    while (grid_cells_for(ext, h) > (double)TET_MAX_GRID_CELLS) h *= 1.25;
  } else {
    double cells = grid_cells_for(ext, h);
    double est = 5 * fabs(surf_vol) / (h * h * h);
    if (cells > (double)TET_MAX_GRID_CELLS || est > 1.5 * TET_MAX_TETS) {
      double hs =
          fmax(cbrt(5 * fabs(surf_vol) / TET_MAX_TETS), cbrt(ext[0] * ext[1] * ext[2] / (double)TET_MAX_GRID_CELLS));
      verr_set(err,
               "tet_mesh_build: too many tetrahedra: edge %g over a %g x %g x %g surface would need about %.0f "
               "(at most %d); use an edge of at least %.3g",
               h, ext[0], ext[1], ext[2], fmax(est, cells), TET_MAX_TETS, hs);
      return 0;
    }
  }
  size_t nin = 0;
  for (int iter = 0; iter < 12; iter++) {
    grid_make(&b->g, ext, h);
    free(b->keep);
    b->keep = malloc(grid_ncells(&b->g));
    if (!b->keep) {
      verr_set(err, "tet_mesh_build: out of memory for a grid of %zu cells", grid_ncells(&b->g));
      return 0;
    }
    nin = classify(s, &b->g, b->keep);
    double tets = 5.0 * (double)nin;
    if (tets > TET_MAX_TETS) {
      if (!automatic) {
        verr_set(err,
                 "tet_mesh_build: too many tetrahedra: edge %g gives %.0f (at most %d); use an edge of at least %.3g",
                 h, tets, TET_MAX_TETS, h * cbrt(tets / TET_MAX_TETS));
        return 0;
      }
      h *= cbrt(tets / (0.9 * TET_MAX_TETS));
      continue;
    }
    if (!automatic || tets >= TET_MIN_TETS) break;
    /* Too coarse for a useful mesh: refine towards ~1,200 tetrahedra, or halve
     * when nothing was inside, as long as the grid stays within bounds. Halving
     * stops at 32 cells across the thinnest extent, and does not start when
     * that extent is below a cell: a flat sheet encloses nothing at any size. */
    double hn = nin ? h * cbrt(tets / (1.2 * TET_MIN_TETS)) : 0.5 * h;
    if (grid_cells_for(ext, hn) > (double)TET_MAX_GRID_CELLS || hn < maxe / (2 * TET_MAX_CELLS_PER_AXIS)) break;
    if (!nin && (mine < hn || mine > 32 * hn)) break;
    h = hn;
  }
  if (5.0 * (double)nin > TET_MAX_TETS) {
    verr_set(err, "tet_mesh_build: too many tetrahedra: %zu even at edge %g (at most %d)", 5 * nin, b->g.h,
             TET_MAX_TETS);
    return 0;
  }
  if (!nin && !automatic && h > 0.5 * mine)
    verr_set(err,
             "tet_mesh_build: nothing is inside the surface at edge %g (winding number below 1/2 at all %zu grid "
             "points): the edge is too coarse for a surface %g thick, or it encloses no volume",
             h, grid_ncells(&b->g), mine);
  else if (!nin)
    verr_set(err,
             "tet_mesh_build: nothing is inside the surface (winding number below 1/2 at all %zu grid points, "
             "spacing %g): it encloses no volume, e.g. an open patch or a flat sheet, and cannot be filled with "
             "tetrahedra",
             grid_ncells(&b->g), b->g.h);
  return nin;
}

int tet_mesh_build(const mesh_t *surface, double target_edge, tet_mesh_t *out, tet_embedding_t *emb,
                   tet_build_report_t *report, verr_t *err) {
  uint64_t t0 = vtime_mono_ns();
  memset(out, 0, sizeof *out);
  if (emb) memset(emb, 0, sizeof *emb);
  if (report) memset(report, 0, sizeof *report);
  if (!surface || surface->nverts == 0 || surface->ntris == 0)
    return verr_set(err, "tet_mesh_build: the surface is empty (%zu vertices, %zu triangles)",
                    surface ? surface->nverts : 0, surface ? surface->ntris : 0);
  if (mesh_validate(surface, "tet_mesh_build: surface", err)) return -1;
  if (surface->ntris > UINT32_MAX / 2)
    return verr_set(err, "tet_mesh_build: %zu triangles are too many", surface->ntris);
  if (!(target_edge >= 0) || !isfinite(target_edge))
    return verr_set(err, "tet_mesh_build: target edge must be >= 0 (0: automatic), got %g", target_edge);

  /* Bounds of the vertices the triangles use: stray unreferenced vertices would
   * only widen the grid. */
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < 3 * surface->ntris; i++) {
    const double *p = surface->pos + 3 * (size_t)surface->tris[i];
    for (int k = 0; k < 3; k++) lo[k] = fmin(lo[k], p[k]), hi[k] = fmax(hi[k], p[k]);
  }
  double centre[3], ext[3];
  for (int k = 0; k < 3; k++) centre[k] = 0.5 * (lo[k] + hi[k]), ext[k] = hi[k] - lo[k];
  if (!(fmax(ext[0], fmax(ext[1], ext[2])) > 0))
    return verr_set(err, "tet_mesh_build: the surface has no extent (all vertices at one point)");

  surf_t s;
  if (surf_init(&s, surface, centre, err)) return -1;
  double surf_vol = surface_volume_local(&s);
  build_t b;
  memset(&b, 0, sizeof b);
  int rc = -1;
  unsigned char *boundary = NULL;
  double *x_grid = NULL;
  size_t nin = choose_grid(&s, ext, target_edge, surf_vol, &b, err);
  if (!nin) goto done;

  /* Nodes: the corners of kept cells, numbered in grid order. */
  const grid_t *g = &b.g;
  size_t ncell = grid_ncells(g), ngnode = (g->n[0] + 1) * (g->n[1] + 1) * (g->n[2] + 1);
  b.node_of = malloc(ngnode * sizeof *b.node_of);
  b.cell_tet = malloc(ncell * sizeof *b.cell_tet);
  out->tets = malloc(20 * nin * sizeof *out->tets);
  if (!b.node_of || !b.cell_tet || !out->tets) {
    verr_set(err, "tet_mesh_build: out of memory for %zu tetrahedra", 5 * nin);
    goto done;
  }
  for (size_t i = 0; i < ngnode; i++) b.node_of[i] = UINT32_MAX;
  size_t nn = 0, c = 0;
  for (size_t k = 0; k < g->n[2]; k++)
    for (size_t j = 0; j < g->n[1]; j++)
      for (size_t i = 0; i < g->n[0]; i++, c++) {
        if (!b.keep[c]) continue;
        for (int q = 0; q < 8; q++) {
          size_t gn = gnode(g, i + (q & 1), j + (q >> 1 & 1), k + (q >> 2 & 1));
          if (b.node_of[gn] == UINT32_MAX) b.node_of[gn] = (uint32_t)nn++;
        }
      }
  out->nnodes = nn;
  out->x = malloc(3 * nn * sizeof *out->x);
  boundary = calloc(nn, 1);
  if (!out->x || !boundary) {
    verr_set(err, "tet_mesh_build: out of memory for %zu nodes", nn);
    goto done;
  }
  /* A node is on the boundary when one of the 8 cells around it is not kept. */
  for (size_t k = 0; k <= g->n[2]; k++)
    for (size_t j = 0; j <= g->n[1]; j++)
      for (size_t i = 0; i <= g->n[0]; i++) {
        uint32_t v = b.node_of[gnode(g, i, j, k)];
        if (v == UINT32_MAX) continue;
        v3_set(out->x + 3 * (size_t)v, g->origin[0] + (double)i * g->h, g->origin[1] + (double)j * g->h,
               g->origin[2] + (double)k * g->h);
        for (int q = 0; q < 8 && !boundary[v]; q++) {
          long ci = (long)i - (q & 1), cj = (long)j - (q >> 1 & 1), ck = (long)k - (q >> 2 & 1);
          if (ci < 0 || cj < 0 || ck < 0 || ci >= (long)g->n[0] || cj >= (long)g->n[1] || ck >= (long)g->n[2] ||
              !b.keep[(size_t)ci + g->n[0] * ((size_t)cj + g->n[1] * (size_t)ck)])
            boundary[v] = 1;
        }
      }
  /* Tetrahedra: 5 per kept cell, split parity by the cell's global index so
   * neighbouring cells' faces match. */
  size_t nt = 0;
  c = 0;
  for (size_t k = 0; k < g->n[2]; k++)
    for (size_t j = 0; j < g->n[1]; j++)
      for (size_t i = 0; i < g->n[0]; i++, c++) {
        b.cell_tet[c] = UINT32_MAX;
        if (!b.keep[c]) continue;
        uint32_t corner[8];
        for (int q = 0; q < 8; q++) corner[q] = b.node_of[gnode(g, i + (q & 1), j + (q >> 1 & 1), k + (q >> 2 & 1))];
        b.cell_tet[c] = (uint32_t)nt;
        emit_cell(corner, (int)((i + j + k) & 1), out->x, out->tets + 4 * nt);
        nt += 5;
      }
  out->ntets = nt;
  /* Node -> tetrahedra, for the quality checks while snapping. */
  b.inc_start = calloc(nn + 1, sizeof *b.inc_start);
  b.inc = malloc(4 * nt * sizeof *b.inc);
  if (!b.inc_start || !b.inc) {
    verr_set(err, "tet_mesh_build: out of memory for %zu tetrahedra", nt);
    goto done;
  }
  for (size_t i = 0; i < 4 * nt; i++) b.inc_start[out->tets[i] + 1]++;
  for (size_t v = 0; v < nn; v++) b.inc_start[v + 1] += b.inc_start[v];
  {
    uint32_t *fill = malloc(nn * sizeof *fill);
    if (!fill) {
      verr_set(err, "tet_mesh_build: out of memory for %zu nodes", nn);
      goto done;
    }
    memcpy(fill, b.inc_start, nn * sizeof *fill);
    for (size_t i = 0; i < 4 * nt; i++) b.inc[fill[out->tets[i]]++] = (uint32_t)(i / 4);
    free(fill);
  }
  x_grid = malloc(3 * nn * sizeof *x_grid);
  if (!x_grid) {
    verr_set(err, "tet_mesh_build: out of memory for %zu nodes", nn);
    goto done;
  }
  memcpy(x_grid, out->x, 3 * nn * sizeof *x_grid);
  snap_boundary(&s, &b, out, boundary, x_grid);

  size_t outside = 0;
  if (emb) {
    emb->nsurf = surface->nverts;
    emb->tet = malloc(surface->nverts * sizeof *emb->tet);
    emb->bary = malloc(4 * surface->nverts * sizeof *emb->bary);
    if (!emb->tet || !emb->bary) {
      verr_set(err, "tet_mesh_build: out of memory embedding %zu vertices", surface->nverts);
      goto done;
    }
    for (size_t v = 0; v < surface->nverts; v++)
      outside += (size_t)embed_vertex(&b, out, s.p + 3 * v, emb->tet + v, emb->bary + 4 * v);
  }

  double vol = 0, qmin = INFINITY, qsum = 0;
  for (size_t i = 0; i < nt; i++) {
    vol += tet_volume(out, out->x, i);
    double q = tet_quality(out, out->x, i);
    qmin = fmin(qmin, q);
    qsum += q;
  }
  for (size_t v = 0; v < nn; v++) v3_add(out->x + 3 * v, out->x + 3 * v, centre);
  if (report) {
    report->nodes = nn;
    report->tets = nt;
    report->min_quality = qmin;
    report->mean_quality = qsum / (double)nt;
    report->volume = vol;
    report->surface_volume = surf_vol;
    report->outside_vertices = outside;
  }
  rc = 0;
done:
  free(x_grid);
  free(boundary);
  build_free(&b);
  surf_free(&s);
  if (rc) {
    tet_mesh_free(out);
    if (emb) tet_embedding_free(emb);
  } else if (report) {
    report->seconds = (double)(vtime_mono_ns() - t0) * 1e-9;
  }
  return rc;
}
