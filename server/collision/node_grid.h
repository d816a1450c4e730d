/* SPDX-License-Identifier: Apache-2.0 */
/* node_grid: a uniform grid over mesh nodes for "which node does the tool
 * touch" queries (docs/methods.md B §4.3, Tables 4.1-4.2: the touched node found by
 * space partitioning instead of a linear scan).
 *
 * The thesis uses an octree of 25-50 nodes per leaf, three levels deep, and
 * searches only the octant the tool point falls in. A uniform grid is used
 * here instead: with a few nodes per occupied cell it reaches the touched
 * node in one or two cell rings, it rebuilds from scratch in O(n) with a
 * counting sort (the thesis notes that recomputing its octree every frame is
 * expensive, so a deforming organ would otherwise need a dynamic tree), and
 * the search is exact: rings are widened until no unvisited cell can hold a
 * nearer node, so a point near an octant wall still gets its true nearest
 * node.
 *
 * Layout: cells in x-fastest order; cell_start[c] .. cell_start[c + 1] index
 * `items` (node ids) and `pts` (their positions, copied so a cell is one run
 * of memory). Create allocates; rebuild and queries never do. Rebuild after
 * the nodes move (each physics step); queries see the positions of the last
 * rebuild. Non-finite nodes (and any beyond 1e100 m) are left out. */
#ifndef VISCERA_NODE_GRID_H
#define VISCERA_NODE_GRID_H

#include <stddef.h>
#include <stdint.h>

#include "verr.h"

#define NODE_GRID_NONE UINT32_MAX

typedef struct node_grid {
  size_t n;         /* nodes (ids 0 .. n-1) */
  size_t ninside;   /* finite nodes, in the grid */
  double cell0;     /* m, cell size chosen at create */
  double cell;      /* m, cell size of the last rebuild (cell0, or larger if the nodes spread out) */
  double inv_cell;
  double lo[3];     /* corner of cell (0, 0, 0) */
  uint32_t dims[3];
  size_t ncells, cap_cells;
  uint32_t *cell_start; /* cap_cells + 1 */
  uint32_t *items;      /* n */
  double *pts;          /* 3n */
  uint32_t *cell_of;    /* n: scratch for the counting sort */
} node_grid_t;

/* Builds the grid over n nodes at x (3 per node). cell <= 0 chooses a size
 * that gives about one cell per node over the bounding box (measured best
 * for surface meshes, whose nodes fill only a shell of it; node_grid.c).
 * Room is reserved for 8x as many cells, so the organ may spread to twice
 * its size along each axis before rebuilds coarsen the cells. Returns 0, or
 * -1 with err. */
int node_grid_create(node_grid_t *g, const double *x, size_t n, double cell, verr_t *err);
void node_grid_destroy(node_grid_t *g);

/* Re-bins all n nodes from positions x (O(n + cells), no allocation). */
void node_grid_rebuild(node_grid_t *g, const double *x);

/* Nearest node to q (ties to the lowest id): its id and squared distance, or
 * NODE_GRID_NONE if the grid is empty or q is not finite. */
uint32_t node_grid_nearest(const node_grid_t *g, const double q[3], double *dist2);

/* Calls fn for every node whose position lies in [lo, hi] (inclusive), in
 * cell order, with its id and grid position. */
typedef void (*node_grid_visit_fn)(void *ctx, uint32_t id, const double p[3]);
void node_grid_visit_box(const node_grid_t *g, const double lo[3], const double hi[3], node_grid_visit_fn fn,
                         void *ctx);

/* The nodes in [lo, hi]: writes up to cap ids to out, returns how many there are. */
size_t node_grid_query_box(const node_grid_t *g, const double lo[3], const double hi[3], uint32_t *out, size_t cap);

#endif
