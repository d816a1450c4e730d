/* SPDX-License-Identifier: Apache-2.0 */
/* ms_cut_sweep: stage 1 of docs/methods.md D's cutting (§2.3.1, Algorithm 1): the
 * swept volume of the tool's circular region along its path, and what it
 * deletes from a triangle surface.
 *
 * The swept region is {p : dist(p, path) < r}, path a polyline of contact
 * points (a single point: a ball). A node is inside when its distance is
 * below r; a spring (edge) when the distance between its segment and the
 * path is below r (a spring the blade passes through has distance 0 even
 * if both its nodes stay outside). Distances are exact (closest points of
 * segments, no sampling).
 *
 * ms_sweep_mark() marks nodes and triangles (a triangle goes when one of its
 * nodes or edges is inside, or when the path runs through it: `hit_tris`).
 * ms_sweep_cleanup() then grows the deletion until the hole's boundary is
 * simple: a surviving triangle with two or more edges on the hole goes, and
 * so do all triangles of a node the hole boundary leaves or enters twice (a
 * pinch), repeated
 * until nothing changes. It reports the hole's boundary as directed edges
 * with the hole on their left (the deleted triangles' own edges whose twins
 * survive) and the springs that were cut (edges of deleted triangles no
 * surviving triangle keeps), for the residual stress.
 * Cost O(n + T) per call; allocates only its outputs and adjacency. */
#ifndef VISCERA_MS_CUT_SWEEP_H
#define VISCERA_MS_CUT_SWEEP_H

#include <stddef.h>
#include <stdint.h>

#include "verr.h"

double ms_sweep_point_path_dist(const double p[3], const double *path, size_t npath);
double ms_sweep_seg_path_dist(const double a[3], const double b[3], const double *path, size_t npath);
/* Distance between segments a0-a1 and b0-b1 (either may be a point). */
double ms_sweep_seg_seg_dist(const double a0[3], const double a1[3], const double b0[3], const double b1[3]);

/* node_in[n], tri_dead[ntris] are written (0/1). */
void ms_sweep_mark(size_t n, const double *x, size_t ntris, const uint32_t *tris, const double *path, size_t npath,
                   double r, const uint32_t *hit_tris, size_t nhit, uint8_t *node_in, uint8_t *tri_dead);

typedef struct ms_sweep_out {
  uint8_t *node_dead; /* n: referenced by no surviving triangle */
  size_t nhole;       /* directed hole edges */
  uint32_t *hole;     /* 2 nhole */
  size_t ncut;        /* springs cut */
  uint32_t *cut;      /* 2 ncut */
  size_t tris_dead, nodes_dead;
} ms_sweep_out_t;

/* tri_dead is updated in place. Returns 0, or -1 with err (OOM, bad index). */
int ms_sweep_cleanup(size_t n, size_t ntris, const uint32_t *tris, uint8_t *tri_dead, ms_sweep_out_t *out, verr_t *err);
void ms_sweep_out_free(ms_sweep_out_t *o);

#endif
