/* SPDX-License-Identifier: Apache-2.0 */
#include "vmath.h"

/* Region-based closest point (Ericson, Real-Time Collision Detection 5.1.5):
 * no square roots, and degenerate triangles fall into an edge or vertex region. */
void tri_closest_point(const double *p, const double *a, const double *b, const double *c, double *out, double *bary) {
  double ab[3], ac[3], ap[3], bp[3], cp[3];
  v3_sub(ab, b, a);
  v3_sub(ac, c, a);
  v3_sub(ap, p, a);
  double d1 = v3_dot(ab, ap), d2 = v3_dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) {
    v3_copy(out, a);
    v3_set(bary, 1, 0, 0);
    return;
  }
  v3_sub(bp, p, b);
  double d3 = v3_dot(ab, bp), d4 = v3_dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) {
    v3_copy(out, b);
    v3_set(bary, 0, 1, 0);
    return;
  }
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    double den = d1 - d3;
    double v = den > 0 ? d1 / den : 0;
    v3_copy(out, a);
    v3_axpy(out, ab, v);
    v3_set(bary, 1 - v, v, 0);
    return;
  }
  v3_sub(cp, p, c);
  double d5 = v3_dot(ab, cp), d6 = v3_dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) {
    v3_copy(out, c);
    v3_set(bary, 0, 0, 1);
    return;
  }
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    double den = d2 - d6;
    double w = den > 0 ? d2 / den : 0;
    v3_copy(out, a);
    v3_axpy(out, ac, w);
    v3_set(bary, 1 - w, 0, w);
    return;
  }
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    double den = (d4 - d3) + (d5 - d6);
    double w = den > 0 ? (d4 - d3) / den : 0;
    double bc[3];
    v3_sub(bc, c, b);
    v3_copy(out, b);
    v3_axpy(out, bc, w);
    v3_set(bary, 0, 1 - w, w);
    return;
  }
  double den = va + vb + vc;
  if (!(den > 0)) { /* degenerate: fall back to vertex a */
    v3_copy(out, a);
    v3_set(bary, 1, 0, 0);
    return;
  }
  double v = vb / den, w = vc / den;
  v3_copy(out, a);
  v3_axpy(out, ab, v);
  v3_axpy(out, ac, w);
  v3_set(bary, 1 - v - w, v, w);
}

/* Moller-Trumbore, two-sided; a near-zero determinant (segment parallel to the
 * plane or a degenerate triangle) is a miss rather than a division by zero. */
int seg_tri_intersect(const double *p0, const double *p1, const double *a, const double *b, const double *c, double *t,
                      double *bary) {
  double dir[3], e1[3], e2[3], pv[3], tv[3], qv[3];
  v3_sub(dir, p1, p0);
  v3_sub(e1, b, a);
  v3_sub(e2, c, a);
  v3_cross(pv, dir, e2);
  double det = v3_dot(e1, pv);
  double scale = v3_norm(e1) * v3_norm(e2) * v3_norm(dir);
  if (!(fabs(det) > 1e-14 * scale) || scale == 0) return 0;
  double inv = 1.0 / det;
  v3_sub(tv, p0, a);
  double u = v3_dot(tv, pv) * inv;
  if (u < 0 || u > 1) return 0;
  v3_cross(qv, tv, e1);
  double v = v3_dot(dir, qv) * inv;
  if (v < 0 || u + v > 1) return 0;
  double tt = v3_dot(e2, qv) * inv;
  if (tt < 0 || tt > 1) return 0;
  *t = tt;
  v3_set(bary, 1 - u - v, u, v);
  return 1;
}

double tri_solid_angle(const double q[3], const double a[3], const double b[3], const double c[3]) {
  double x[3], y[3], z[3], yz[3];
  v3_sub(x, a, q);
  v3_sub(y, b, q);
  v3_sub(z, c, q);
  double lx = v3_norm(x), ly = v3_norm(y), lz = v3_norm(z);
  v3_cross(yz, y, z);
  double num = v3_dot(x, yz);
  double den = lx * ly * lz + v3_dot(x, y) * lz + v3_dot(y, z) * lx + v3_dot(z, x) * ly;
  return 2 * atan2(num, den);
}
