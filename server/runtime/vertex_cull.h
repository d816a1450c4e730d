/* SPDX-License-Identifier: Apache-2.0 */
/* vertex_cull: the surface vertices that lie in a box, from the organ's
 * AABB tree, in ascending index order (issue 17: the contact patch and the
 * shaft's node test scanned every surface vertex each step or sub-step).
 *
 * How: down the tree through the nodes whose boxes overlap the query box;
 * at each leaf, the corners of its triangles are tested where they are now
 * (x, the array the tree reads), and those inside the box are kept.
 * Completeness: the refit (at the end of every step, runtime/scene_runtime.c)
 * leaves every leaf box containing each of its vertices' positions of that
 * moment (aabb_tree.h: xr +- margin, and no vertex beyond its margin), and
 * every ancestor box contains the leaf's, so a vertex that
 * - is a corner of some triangle (checked at setup: `complete`), and
 * - has not moved since the tree was refit or built
 * and lies in the box is found. A vertex that may have moved since is the
 * caller's to add (vertex_cull_add: the model says which,
 * model.h surface_moved). The callers grow the box by VERTEX_CULL_PAD
 * (relative) beyond their own test's radius to cover its rounding, then run
 * the scan's own per-vertex test over the candidates in ascending order,
 * so their results are the scan's bit for bit. An incomplete surface, a
 * tree over another surface or position array, or a NaN query give
 * SIZE_MAX: the caller scans every vertex. (The models' guard keeps
 * positions finite between steps, model_guard.h.)
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

/* Relative growth of a query box over the caller's radius (the distance
 * tests round at ~1e-16 relative). */
#define VERTEX_CULL_PAD 1e-9

typedef struct vertex_cull {
  size_t nverts, ntris; /* the surface it was set up for */
  int complete;         /* every vertex is a corner of some triangle */
  uint64_t *bits;       /* (nverts + 63) / 64 words, zero between gatherings */
  size_t wlo, whi;      /* the words set so far: [wlo, whi) */
  uint32_t *out;        /* nverts: the candidates, ascending */
  int overflow;         /* the gathering under way cannot vouch for its result (NaN query) */
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
 * box adds every vertex in [lo, hi] (closed) that has not moved since the
 * tree's last refit (above); add adds vertex i (< nverts; others are
 * ignored). take returns the distinct candidates in ascending order (*out:
 * c's memory, valid until the next gathering) and their count, or SIZE_MAX
 * when the gathering could not vouch for them; either way c is clear
 * again. */
void vertex_cull_begin(vertex_cull_t *c);
void vertex_cull_box(vertex_cull_t *c, const aabb_tree_t *tree, const double lo[3], const double hi[3]);
void vertex_cull_add(vertex_cull_t *c, uint32_t i);
size_t vertex_cull_take(vertex_cull_t *c, const uint32_t **out);

/* The candidates for the points within `radius` of segment p0 -> p1 (the
 * shaft's cylinder, and the box the shaft's node test starts from), plus
 * the nmoved vertices of `moved` (those that may have left the positions
 * the tree's boxes fit). SIZE_MAX: scan. */
size_t vertex_cull_segment(vertex_cull_t *c, const aabb_tree_t *tree, const double p0[3], const double p1[3],
                           double radius, const uint32_t *moved, size_t nmoved, const uint32_t **out);

#endif
