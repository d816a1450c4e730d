/* SPDX-License-Identifier: Apache-2.0 */
#include "collision/node_grid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Cells per node over the bounding box when the caller leaves the size to
 * us. A surface mesh fills only a shell of its box, so this gives ~7 nodes
 * per occupied cell on the organs; 0.5-8 were measured on the liver (23,522
 * nodes, random points within 5 mm of the surface) and 1 was fastest. */
#define AUTO_CELLS_PER_NODE 1.0
/* Extra room for cells, so a deformed organ keeps its cell size. */
#define CELL_RESERVE 8

/* Non-finite nodes, and nodes absurdly far away (a blown-up simulation),
 * are left out: one at 1e300 m would make every rebuild coarsen the cells
 * without end. */
static inline int usable(const double *p) {
  return fabs(p[0]) < 1e100 && fabs(p[1]) < 1e100 && fabs(p[2]) < 1e100;
}

static int bounds(const double *x, size_t n, double lo[3], double hi[3]) {
  int any = 0;
  for (int k = 0; k < 3; k++) {
    lo[k] = INFINITY;
    hi[k] = -INFINITY;
  }
  for (size_t i = 0; i < n; i++) {
    const double *p = x + 3 * i;
    if (!usable(p)) continue;
    any = 1;
    for (int k = 0; k < 3; k++) {
      if (p[k] < lo[k]) lo[k] = p[k];
      if (p[k] > hi[k]) hi[k] = p[k];
    }
  }
  return any;
}

/* Cells along each axis for cell size h; the product as a double so a
 * far-flung node cannot overflow it. */
static double dims_for(const double lo[3], const double hi[3], double h, uint32_t dims[3]) {
  double total = 1;
  for (int k = 0; k < 3; k++) {
    double d = floor((hi[k] - lo[k]) / h) + 1;
    total *= d;
    dims[k] = d < 4e9 ? (uint32_t)d : 4000000000u;
  }
  return total;
}

int node_grid_create(node_grid_t *g, const double *x, size_t n, double cell, verr_t *err) {
  memset(g, 0, sizeof *g);
  if (n >= UINT32_MAX) return verr_set(err, "node_grid: %zu nodes, more than 32-bit ids allow", n);
  double lo[3], hi[3];
  if (!bounds(x, n, lo, hi)) {
    lo[0] = lo[1] = lo[2] = hi[0] = hi[1] = hi[2] = 0;
  }
  if (!(cell > 0)) {
    /* Size from the box's volume over the axes it really spans: a flat patch
     * has no depth, and cells sized by a zero volume would be zero. */
    double ext = 0, vol = 1;
    int dims = 0;
    for (int k = 0; k < 3; k++) ext = fmax(ext, hi[k] - lo[k]);
    for (int k = 0; k < 3; k++)
      if (hi[k] - lo[k] > 1e-6 * ext) {
        vol *= hi[k] - lo[k];
        dims++;
      }
    cell = dims ? pow(vol / (AUTO_CELLS_PER_NODE * (double)(n ? n : 1)), 1.0 / dims) : 1.0;
    if (!(cell > 0) || !isfinite(cell)) cell = 1.0;
  }
  uint32_t d[3];
  double want = dims_for(lo, hi, cell, d) * CELL_RESERVE;
  size_t cap = want < 64 ? 64 : (want > 1 << 28 ? (size_t)1 << 28 : (size_t)want);
  g->n = n;
  g->cell0 = cell;
  g->cap_cells = cap;
  g->cell_start = malloc((cap + 1) * sizeof *g->cell_start);
  g->items = malloc((n ? n : 1) * sizeof *g->items);
  g->pts = malloc((n ? 3 * n : 1) * sizeof *g->pts);
  g->cell_of = malloc((n ? n : 1) * sizeof *g->cell_of);
  if (!g->cell_start || !g->items || !g->pts || !g->cell_of) {
    node_grid_destroy(g);
    return verr_set(err, "node_grid: out of memory for %zu nodes", n);
  }
  node_grid_rebuild(g, x);
  return 0;
}

void node_grid_destroy(node_grid_t *g) {
  free(g->cell_start);
  free(g->items);
  free(g->pts);
  free(g->cell_of);
  memset(g, 0, sizeof *g);
}

static inline uint32_t clamp_cell(double v, uint32_t dim) {
  if (!(v > 0)) return 0;
  if (v >= (double)dim) return dim - 1;
  return (uint32_t)v;
}

void node_grid_rebuild(node_grid_t *g, const double *x) {
  double lo[3], hi[3];
  if (!bounds(x, g->n, lo, hi)) lo[0] = lo[1] = lo[2] = hi[0] = hi[1] = hi[2] = 0;
  /* Keep the create-time cell size unless the nodes spread beyond the
   * reserved cells; then coarsen until they fit (never allocate here). */
  double h = g->cell0;
  while (dims_for(lo, hi, h, g->dims) > (double)g->cap_cells) h *= 1.25992104989; /* 2^(1/3): ~2x fewer cells */
  g->cell = h;
  g->inv_cell = 1.0 / h;
  for (int k = 0; k < 3; k++) g->lo[k] = lo[k];
  g->ncells = (size_t)g->dims[0] * g->dims[1] * g->dims[2];
  uint32_t *start = g->cell_start;
  memset(start, 0, (g->ncells + 1) * sizeof *start);
  size_t inside = 0;
  for (size_t i = 0; i < g->n; i++) {
    const double *p = x + 3 * i;
    if (!usable(p)) {
      g->cell_of[i] = UINT32_MAX;
      continue;
    }
    uint32_t c[3];
    for (int k = 0; k < 3; k++) c[k] = clamp_cell((p[k] - lo[k]) * g->inv_cell, g->dims[k]);
    uint32_t cell = (c[2] * g->dims[1] + c[1]) * g->dims[0] + c[0];
    g->cell_of[i] = cell;
    start[cell + 1]++;
    inside++;
  }
  g->ninside = inside;
  /* Counting sort: prefix sums give each cell's first slot; filling in id
   * order keeps ids ascending within a cell. */
  for (size_t c = 0; c < g->ncells; c++) start[c + 1] += start[c];
  for (size_t i = 0; i < g->n; i++) {
    uint32_t cell = g->cell_of[i];
    if (cell == UINT32_MAX) continue;
    uint32_t slot = start[cell]++;
    g->items[slot] = (uint32_t)i;
    for (int k = 0; k < 3; k++) g->pts[3 * (size_t)slot + (size_t)k] = x[3 * i + (size_t)k];
  }
  /* The fill advanced every start to its cell's end; shift back. */
  for (size_t c = g->ncells; c > 0; c--) start[c] = start[c - 1];
  start[0] = 0;
}

static inline void scan_cell(const node_grid_t *g, size_t cell, const double q[3], double *best, uint32_t *best_id) {
  for (uint32_t s = g->cell_start[cell]; s < g->cell_start[cell + 1]; s++) {
    const double *p = g->pts + 3 * (size_t)s;
    double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
    double d2 = dx * dx + dy * dy + dz * dz;
    uint32_t id = g->items[s];
    if (d2 < *best || (d2 == *best && id < *best_id)) {
      *best = d2;
      *best_id = id;
    }
  }
}

uint32_t node_grid_nearest(const node_grid_t *g, const double q[3], double *dist2) {
  if (!g->ninside || !(isfinite(q[0]) && isfinite(q[1]) && isfinite(q[2]))) {
    if (dist2) *dist2 = INFINITY;
    return NODE_GRID_NONE;
  }
  int64_t c[3], dim[3];
  for (int k = 0; k < 3; k++) {
    dim[k] = g->dims[k];
    c[k] = clamp_cell((q[k] - g->lo[k]) * g->inv_cell, g->dims[k]);
  }
  double best = INFINITY;
  uint32_t best_id = NODE_GRID_NONE;
  /* A margin of a billionth of a cell absorbs rounding in the binning, so
   * the stopping bound stays a true lower bound. */
  double slack = 1e-9 * g->cell;
  for (int64_t r = 0;; r++) {
    /* Ring r: cells at Chebyshev distance exactly r from c, clipped to the grid. */
    int64_t z0 = c[2] - r < 0 ? 0 : c[2] - r, z1 = c[2] + r >= dim[2] ? dim[2] - 1 : c[2] + r;
    int64_t y0 = c[1] - r < 0 ? 0 : c[1] - r, y1 = c[1] + r >= dim[1] ? dim[1] - 1 : c[1] + r;
    int64_t x0 = c[0] - r < 0 ? 0 : c[0] - r, x1 = c[0] + r >= dim[0] ? dim[0] - 1 : c[0] + r;
    for (int64_t z = z0; z <= z1; z++) {
      int zface = z == c[2] - r || z == c[2] + r;
      for (int64_t y = y0; y <= y1; y++) {
        int yface = zface || y == c[1] - r || y == c[1] + r;
        size_t row = ((size_t)z * g->dims[1] + (size_t)y) * g->dims[0];
        if (yface) {
          for (int64_t xx = x0; xx <= x1; xx++) scan_cell(g, row + (size_t)xx, q, &best, &best_id);
        } else { /* inside the shell in y and z: only the two x faces belong to the ring */
          if (c[0] - r >= 0) scan_cell(g, row + (size_t)(c[0] - r), q, &best, &best_id);
          if (c[0] + r < dim[0]) scan_cell(g, row + (size_t)(c[0] + r), q, &best, &best_id);
        }
      }
    }
    /* Every unvisited cell lies outside the cube of rings 0..r; the query's
     * distance to that cube's open faces bounds any node left. */
    double bound = INFINITY;
    for (int k = 0; k < 3; k++) {
      if (c[k] - r > 0) bound = fmin(bound, q[k] - (g->lo[k] + (double)(c[k] - r) * g->cell));
      if (c[k] + r + 1 < dim[k]) bound = fmin(bound, g->lo[k] + (double)(c[k] + r + 1) * g->cell - q[k]);
    }
    if (bound == INFINITY) break; /* the whole grid has been scanned */
    bound -= slack;
    if (bound > 0 && best <= bound * bound) break;
  }
  if (dist2) *dist2 = best;
  return best_id;
}

void node_grid_visit_box(const node_grid_t *g, const double lo[3], const double hi[3], node_grid_visit_fn fn, void *ctx) {
  if (!g->ninside) return;
  uint32_t c0[3], c1[3];
  for (int k = 0; k < 3; k++) {
    if (!(lo[k] <= hi[k])) return;
    c0[k] = clamp_cell((lo[k] - g->lo[k]) * g->inv_cell, g->dims[k]);
    c1[k] = clamp_cell((hi[k] - g->lo[k]) * g->inv_cell, g->dims[k]);
  }
  for (uint32_t z = c0[2]; z <= c1[2]; z++)
    for (uint32_t y = c0[1]; y <= c1[1]; y++) {
      size_t row = ((size_t)z * g->dims[1] + y) * g->dims[0];
      for (uint32_t s = g->cell_start[row + c0[0]]; s < g->cell_start[row + c1[0] + 1]; s++) {
        const double *p = g->pts + 3 * (size_t)s;
        if (p[0] < lo[0] || p[0] > hi[0] || p[1] < lo[1] || p[1] > hi[1] || p[2] < lo[2] || p[2] > hi[2]) continue;
        fn(ctx, g->items[s], p);
      }
    }
}

typedef struct collect_ctx {
  uint32_t *out;
  size_t cap, count;
} collect_ctx_t;

static void collect(void *ctx, uint32_t id, const double p[3]) {
  (void)p;
  collect_ctx_t *c = ctx;
  if (c->count < c->cap) c->out[c->count] = id;
  c->count++;
}

size_t node_grid_query_box(const node_grid_t *g, const double lo[3], const double hi[3], uint32_t *out, size_t cap) {
  collect_ctx_t c = {out, cap, 0};
  node_grid_visit_box(g, lo, hi, collect, &c);
  return c.count;
}
