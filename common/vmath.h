/* SPDX-License-Identifier: Apache-2.0 */
/* vmath: small 3-vector helpers on double[3]. Header-only, no allocation.
 * Normalisation is guarded: a zero vector stays zero instead of becoming NaN. */
#ifndef VISCERA_VMATH_H
#define VISCERA_VMATH_H

#include <math.h>

static inline void v3_set(double *r, double x, double y, double z) {
  r[0] = x;
  r[1] = y;
  r[2] = z;
}
static inline void v3_copy(double *r, const double *a) {
  r[0] = a[0];
  r[1] = a[1];
  r[2] = a[2];
}
static inline void v3_add(double *r, const double *a, const double *b) {
  r[0] = a[0] + b[0];
  r[1] = a[1] + b[1];
  r[2] = a[2] + b[2];
}
static inline void v3_sub(double *r, const double *a, const double *b) {
  r[0] = a[0] - b[0];
  r[1] = a[1] - b[1];
  r[2] = a[2] - b[2];
}
static inline void v3_scale(double *r, const double *a, double s) {
  r[0] = a[0] * s;
  r[1] = a[1] * s;
  r[2] = a[2] * s;
}
/* r += a * s */
static inline void v3_axpy(double *r, const double *a, double s) {
  r[0] += a[0] * s;
  r[1] += a[1] * s;
  r[2] += a[2] * s;
}
static inline double v3_dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static inline void v3_cross(double *r, const double *a, const double *b) {
  double x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
  r[0] = x;
  r[1] = y;
  r[2] = z;
}
static inline double v3_norm(const double *a) { return sqrt(v3_dot(a, a)); }
static inline double v3_dist(const double *a, const double *b) {
  double d[3];
  v3_sub(d, a, b);
  return v3_norm(d);
}
/* Normalises in place; returns the original length. Lengths below 1e-300
 * leave the vector unchanged (zero) so degenerate geometry never yields NaN. */
static inline double v3_normalize(double *a) {
  double n = v3_norm(a);
  if (n > 1e-300) v3_scale(a, a, 1.0 / n);
  return n;
}
static inline int v3_isfinite(const double *a) { return isfinite(a[0]) && isfinite(a[1]) && isfinite(a[2]); }

/* Closest point on triangle (a,b,c) to p; barycentric weights of the result in
 * bary (sum 1). Robust for degenerate triangles. */
void tri_closest_point(const double *p, const double *a, const double *b, const double *c, double *out, double *bary);

/* Segment p0->p1 against triangle (a,b,c), two-sided. Returns 1 and the
 * segment parameter t in [0,1] and barycentrics on a hit, else 0. */
int seg_tri_intersect(const double *p0, const double *p1, const double *a, const double *b, const double *c, double *t,
                      double *bary);

/* Signed solid angle of triangle (a, b, c) seen from q (Van Oosterom and
 * Strackee): positive when q sees the triangle's back, i.e. q is on the
 * inner side of a counter-clockwise (outward) triangle. Summed over a closed
 * outward surface and divided by 4 pi it is the winding number of q. */
double tri_solid_angle(const double q[3], const double a[3], const double b[3], const double c[3]);

#endif
