/* shaft: the tool shaft against tissue (issue 4; seed 004 §2.2 cylinder
 * test). The shaft is a cylinder of radius SHAFT_RADIUS_FRACTION x the tip
 * radius (as the viewer draws it) around the segment from just above the
 * tip sphere to tip + length along the tool axis (the command's orientation
 * applied to +z). Every organ surface vertex inside it is pushed radially
 * out of it by a penalty spring of the tool's stiffness (at most
 * SHAFT_MAX_VERTEX_FORCE per vertex); the tool gets the sum of the
 * reactions (clamped to its max force). A vertical probe pressing with its
 * tip touches nothing with its shaft; a tilted tool laid on tissue does.
 * No allocation. */
#ifndef VISCERA_SHAFT_H
#define VISCERA_SHAFT_H

#include <stddef.h>
#include <stdint.h>

#define SHAFT_RADIUS_FRACTION 0.45
#define SHAFT_MAX_VERTEX_FORCE 0.2 /* N */

/* Unit tool axis: +z rotated by the unit quaternion q (w, x, y, z). */
void shaft_axis(const double q[4], double axis[3]);

/* The shaft segment of a tool with its tip at `tip`. */
void shaft_segment(const double tip[3], const double axis[3], double tip_radius, double length, double p0[3],
                   double p1[3]);

/* Penalty forces on the vertices of x (n) inside the shaft: calls
 * add(ctx, i, f) for each, accumulates the reaction on the tool into
 * f_tool (not reset) and returns the count. */
size_t shaft_push(const double p0[3], const double p1[3], double radius, double k, const double *x, size_t n,
                  void (*add)(void *ctx, uint32_t i, const double f[3]), void *ctx, double f_tool[3]);

#endif
