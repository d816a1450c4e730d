/* SPDX-License-Identifier: Apache-2.0 */
/* shaft: the tool shaft against tissue (issue 4; docs/methods.md D §2.2 cylinder
 * test, plus segment-triangle contact). The shaft is a cylinder of radius
 * SHAFT_RADIUS_FRACTION x the tip radius (as the viewer draws it) around the
 * segment from just above the tip sphere to tip + length along the tool
 * axis (the command's orientation applied to +z). A vertical probe pressing
 * with its tip touches nothing with its shaft; a tilted tool laid on tissue
 * does.
 *
 * Two tests, one penalty law (a spring of the tool's stiffness k on the
 * depth inside the cylinder, at most SHAFT_MAX_VERTEX_FORCE per vertex):
 * - node test: every surface vertex inside the cylinder is pushed radially
 *   out of it, k (radius - distance to the axis);
 * - crossing test: a coarse triangle whose interior the axis crosses while
 *   all its corners lie outside the cylinder escapes the node test. For each
 *   triangle the segment crosses, the crossing point lies on the axis, a
 *   full radius deep: the force min(k radius, SHAFT_MAX_VERTEX_FORCE) is
 *   split over the triangle's corners by the barycentric coordinates of the
 *   crossing, along the triangle's inward normal (-n) with its component
 *   along the axis removed (the tissue is pushed back to the side it lies
 *   on, and off the axis); a triangle facing the axis head-on (that part
 *   under 1e-6 of |n|) pushes each corner radially away from the axis.
 * Never a double push: a vertex inside the cylinder gets the node force
 * only (its crossing shares are dropped), and a corner shared by several
 * crossed triangles gets the sum of its shares clamped to
 * SHAFT_MAX_VERTEX_FORCE, so no vertex ever gets more than
 * SHAFT_MAX_VERTEX_FORCE from one shaft in one call. At most
 * SHAFT_MAX_CROSSINGS crossings count, the first along the shaft from the
 * tip (ties to the lower triangle index); a straight shaft crosses a surface
 * a handful of times, so the cap only bounds work on a crumpled mesh.
 *
 * The crossings are found through the organ's AABB tree when one is given
 * (box queries over pieces of the segment, each answered into a fixed
 * buffer; a piece with too many candidates is halved), else by a scan of
 * every triangle; both give the same crossings in the same order, so the
 * same forces to the bit. The tree's boxes may be stale: fit to earlier
 * positions from which no vertex of x has moved more than `slack` (every
 * query box is grown by it; the triangle tests read x itself). Inside the
 * model's sub-step hook the tree was refit at the start of the scene step
 * and surface models have moved since; refitting there would cost 30-40 %
 * of a sub-step (kidney 20 us, liver_large 240 us), so the caller passes
 * slack = the shaft radius: a crossing is missed only by tissue that came
 * more than a shaft radius within one step (over 1.35 m/s for a 3 mm tool
 * at 1 kHz: a blown-up model), and then it is found one step late, at the
 * next step's refit. The shaft itself only moves between steps, so a
 * moving tool never outruns the tree.
 * The tool gets the sum of the reactions. No allocation. */
#ifndef VISCERA_SHAFT_H
#define VISCERA_SHAFT_H

#include <stddef.h>
#include <stdint.h>

#include "collision/aabb_tree.h"

#define SHAFT_RADIUS_FRACTION 0.45
#define SHAFT_MAX_VERTEX_FORCE 0.2 /* N */
#define SHAFT_MAX_CROSSINGS 32

/* Unit tool axis: +z rotated by the unit quaternion q (w, x, y, z). */
void shaft_axis(const double q[4], double axis[3]);

/* The shaft segment of a tool with its tip at `tip`. */
void shaft_segment(const double tip[3], const double axis[3], double tip_radius, double length, double p0[3],
                   double p1[3]);

typedef void (*shaft_add_fn)(void *ctx, uint32_t i, const double f[3]);

/* Node test only: penalty forces on the vertices of x (n) inside the shaft:
 * calls add(ctx, i, f) for each, accumulates the reaction on the tool into
 * f_tool (not reset) and returns the count. */
size_t shaft_push(const double p0[3], const double p1[3], double radius, double k, const double *x, size_t n,
                  shaft_add_fn add, void *ctx, double f_tool[3]);
/* The same test over the vertices idx (nidx of them, each < the count of
 * x): with every vertex the test can push among them, in ascending order,
 * the forces, their order and the reaction are shaft_push's to the bit
 * (runtime/vertex_cull.h gathers such lists from the organ's tree). */
size_t shaft_push_list(const double p0[3], const double p1[3], double radius, double k, const double *x,
                       const uint32_t *idx, size_t nidx, shaft_add_fn add, void *ctx, double f_tool[3]);

/* A contact surface: positions x (3 n), triangles tris (3 ntris, indices
 * < n) and optionally the AABB tree over them (NULL: scan every triangle),
 * whose boxes fit x. */
typedef struct shaft_surface {
  const double *x;
  size_t n;
  const uint32_t *tris;
  size_t ntris;
  const aabb_tree_t *tree;
  double slack; /* m the surface may have moved since the tree's refit */
  /* The node test's candidates (NULL: every vertex), see shaft_push_list. */
  const uint32_t *cand;
  size_t ncand;
} shaft_surface_t;

typedef struct shaft_stats {
  size_t nodes;     /* vertices pushed by the node test */
  size_t crossings; /* triangles crossed by the segment (capped) */
  size_t corners;   /* distinct vertices pushed for crossings */
} shaft_stats_t;

/* Crossings of segment p0 -> p1 with the surface's triangles, sorted by
 * (t, triangle); writes up to cap (<= SHAFT_MAX_CROSSINGS) triangle indices
 * and parameters, returns how many. */
size_t shaft_crossings(const double p0[3], const double p1[3], const shaft_surface_t *s, uint32_t *tri, double *t,
                       double (*bary)[3], size_t cap);

/* Both tests on one surface (see above): forces through add, the reaction
 * summed into f_tool (not reset), the counts into *st (may be NULL).
 * Returns the number of vertices pushed. */
size_t shaft_contact(const double p0[3], const double p1[3], double radius, double k, const shaft_surface_t *s,
                     shaft_add_fn add, void *ctx, double f_tool[3], shaft_stats_t *st);

#endif
