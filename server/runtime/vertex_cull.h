/* SPDX-License-Identifier: Apache-2.0 */
/* vertex_cull: the surface vertices that can lie in a box, from the organ's
 * AABB tree, in ascending index order (issue 17: the contact patch and the
 * shaft's node test scanned every surface vertex each step or sub-step).
 *
 * Completeness: a vertex inside a box is a corner of every triangle that
 * uses it, and each such triangle overlaps the box (touching counts), so
 * the corners of the triangles aabb_tree_box_query returns include every
 * vertex in the box, provided that
 * - every vertex is used by some triangle (checked at setup: `complete`),
 * - the tree's boxes fit the positions the triangle tests read (the tree
 *   is refit at the end of every step, runtime/scene_runtime.c; a vertex
 *   that moved since is added by the caller, see vertex_cull_add),
 * - the box is grown by a little more than the rounding of the caller's
 *   own distance test (the callers grow it by VERTEX_CULL_PAD relative),
 * - no position is NaN (a triangle with a NaN corner overlaps nothing; the
 *   models' guard keeps positions finite between steps, model_guard.h).
 * A query that overflows the fixed buffer, a tree over another surface or
 * an incomplete surface gives SIZE_MAX: the caller scans every vertex.
 * The callers run the scan's own per-vertex test over the candidates in
 * ascending order, so their results are the scan's bit for bit.
 *
 * Ownership: one per organ (organ_rt.h), set up where the tree is built
 * and again where the topology is followed; the gathering calls never
 * allocate. Not thread-safe: one physics thread. */
#ifndef VISCERA_VERTEX_CULL_H
#define VISCERA_VERTEX_CULL_H

#include <stddef.h>
#include <stdint.h>

#include "collision/aabb_tree.h"
#include "verr.h"

/* Triangles one box query may return; more: SIZE_MAX (scan). */
#define VERTEX_CULL_TRI_CAP 2048
/* Relative growth of a query box over the caller's radius (the distance
 * tests round at ~1e-16 relative). */
#define VERTEX_CULL_PAD 1e-9

typedef struct vertex_cull {
  size_t nverts, ntris; /* the surface it was set up for */
  int complete;         /* every vertex is a corner of some triangle */
  uint64_t *bits;       /* (nverts + 63) / 64 words, zero between gatherings */
  size_t wlo, whi;      /* the words set so far: [wlo, whi) */
  uint32_t *tris;       /* VERTEX_CULL_TRI_CAP: a query's answer */
  uint32_t *out;        /* nverts: the candidates, ascending */
  int overflow;         /* the gathering under way lost a query */
} vertex_cull_t;

/* (Re)sets c up for a surface of nverts vertices and these triangles;
 * frees what it had. 0, or -1 with err (out of memory: c is then unusable
 * and every gathering gives SIZE_MAX). */
int vertex_cull_setup(vertex_cull_t *c, size_t nverts, const uint32_t *tris, size_t ntris, verr_t *err);
void vertex_cull_free(vertex_cull_t *c);

/* 1 when c can gather over tree for a surface of nverts vertices and ntris
 * triangles at positions x (the tree reads x: the same array). */
int vertex_cull_usable(const vertex_cull_t *c, const aabb_tree_t *tree, const double *x, size_t nverts, size_t ntris);

/* Gathering: begin, any number of boxes and single vertices, then take.
 * box adds the corners of every triangle overlapping [lo, hi] (tris: the
 * surface's triangles the tree was built over, 3 each); add adds
 * vertex i (< nverts). take returns the distinct candidates in ascending
 * order (*out: c's memory, valid until the next gathering) and their
 * count, or SIZE_MAX when a box overflowed; either way c is clear again. */
void vertex_cull_begin(vertex_cull_t *c);
void vertex_cull_box(vertex_cull_t *c, const aabb_tree_t *tree, const uint32_t *tris, const double lo[3],
                     const double hi[3]);
void vertex_cull_add(vertex_cull_t *c, uint32_t i);
size_t vertex_cull_take(vertex_cull_t *c, const uint32_t **out);

/* The candidates for the points within `radius` of segment p0 -> p1 (the
 * shaft's cylinder, and the box the shaft's node test starts from), plus
 * the nmoved vertices of `moved` (those that may have left the positions
 * the tree's boxes fit). SIZE_MAX: scan. */
size_t vertex_cull_segment(vertex_cull_t *c, const aabb_tree_t *tree, const uint32_t *tris, const double p0[3],
                           const double p1[3], double radius, const uint32_t *moved, size_t nmoved,
                           const uint32_t **out);

#endif
