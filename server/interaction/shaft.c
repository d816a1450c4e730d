#include "shaft.h"

#include <math.h>

#include "collision/cylinder.h"
#include "vmath.h"

void shaft_axis(const double q[4], double axis[3]) {
  double w = q[0], x = q[1], y = q[2], z = q[3];
  /* Third column of the rotation matrix: R e_z. */
  v3_set(axis, 2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y));
  if (!(v3_normalize(axis) > 0.5)) v3_set(axis, 0, 0, 1); /* not a rotation: keep the tool upright */
}

void shaft_segment(const double tip[3], const double axis[3], double tip_radius, double length, double p0[3],
                   double p1[3]) {
  /* The shaft starts where it leaves the tip sphere: the sphere is the
   * god-object's business, the shaft must not fight it. */
  double start = fmin(tip_radius * (1 + SHAFT_RADIUS_FRACTION), length);
  v3_copy(p0, tip);
  v3_axpy(p0, axis, start);
  v3_copy(p1, tip);
  v3_axpy(p1, axis, length);
}

size_t shaft_push(const double p0[3], const double p1[3], double radius, double k, const double *x, size_t n,
                  void (*add)(void *ctx, uint32_t i, const double f[3]), void *ctx, double f_tool[3]) {
  cylinder_t c;
  v3_copy(c.p0, p0);
  v3_copy(c.p1, p1);
  c.radius = radius;
  /* Broad phase: the shaft's box, grown by the radius. */
  double lo[3], hi[3];
  for (int j = 0; j < 3; j++) {
    lo[j] = fmin(p0[j], p1[j]) - radius;
    hi[j] = fmax(p0[j], p1[j]) + radius;
  }
  size_t hits = 0;
  for (size_t i = 0; i < n; i++) {
    const double *v = x + 3 * i;
    if (v[0] < lo[0] || v[0] > hi[0] || v[1] < lo[1] || v[1] > hi[1] || v[2] < lo[2] || v[2] > hi[2]) continue;
    cylinder_hit_t h;
    if (!cylinder_test_node(&c, v, &h) || v3_norm(h.dir) < 0.5) continue; /* on the axis: no direction */
    double mag = fmin(k * (radius - h.dist), SHAFT_MAX_VERTEX_FORCE), f[3];
    v3_scale(f, h.dir, -mag); /* dir points to the axis: push the other way */
    add(ctx, (uint32_t)i, f);
    v3_axpy(f_tool, f, -1);
    hits++;
  }
  return hits;
}
