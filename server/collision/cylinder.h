/* SPDX-License-Identifier: Apache-2.0 */
/* cylinder: a long, thin tool (scalpel, laparoscope shaft) against mesh
 * nodes (docs/methods.md D §2.2).
 *
 * The tool is a cylinder of radius r around its axis segment p0 -> p1. A
 * node N collides when
 *   1. angle p0 p1 N <= 90 degrees and angle p1 p0 N <= 90 degrees (N lies
 *      between the two end planes; the seed's two angle tests), and
 *   2. its distance d to the axis is below r (the radius test).
 * The angle tests are evaluated as the signs of the dot products
 * (p0 - p1) . (N - p1) and (p1 - p0) . (N - p0): the same test without acos,
 * and exact at the end planes. A node on an end plane counts; one exactly at
 * distance r does not (the seed: d < r). Force feedback acts on N along N -> p,
 * p the axis point nearest N.
 * A zero-length axis degenerates to a sphere of radius r around p0.
 * No allocation. */
#ifndef VISCERA_CYLINDER_H
#define VISCERA_CYLINDER_H

#include <stddef.h>
#include <stdint.h>

#include "collision/node_grid.h"

typedef struct cylinder {
  double p0[3], p1[3]; /* axis ends, m */
  double radius;       /* m */
} cylinder_t;

typedef struct cylinder_hit {
  uint32_t node;
  double t;      /* axis parameter of p in [0, 1] (p = p0 + t (p1 - p0)) */
  double dist;   /* d = |N - p| < radius */
  double dir[3]; /* unit N -> p, the direction the published test (docs/methods.md D) pushes the node; zero when N is on
                    the axis */
} cylinder_hit_t;

/* The seed's test for one node; fills *hit (node field untouched) when N is
 * inside. Returns 1 if inside. */
int cylinder_test_node(const cylinder_t *c, const double n[3], cylinder_hit_t *hit);

/* Every node of x (n nodes) inside the cylinder, by a scan (the seed's
 * per-frame loop). Writes up to cap hits, in node order; returns the count. */
size_t cylinder_nodes_scan(const cylinder_t *c, const double *x, size_t n, cylinder_hit_t *out, size_t cap);

/* The same set from a node grid: only nodes in the cylinder's bounding box
 * are tested. Hits come in grid order, not node order. */
size_t cylinder_nodes_grid(const cylinder_t *c, const node_grid_t *g, cylinder_hit_t *out, size_t cap);

#endif
