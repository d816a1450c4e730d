/* SPDX-License-Identifier: Apache-2.0 */
#include "cutting/bezier.h"

#include <math.h>

#include "vmath.h"

double bezier_bernstein(int k, int n, double a) {
  if (n < 0 || n > 20 || k < 0 || k > n) return 0;
  /* n! / (k! (n-k)!) as a running product: exact in double for n <= 20. */
  double binom = 1;
  for (int i = 1; i <= k; i++) binom = binom * (double)(n - k + i) / (double)i;
  return binom * pow(a, k) * pow(1 - a, n - k);
}

void bezier_eval(const double ctrl[4][3], double a, double out[3]) {
  double b = 1 - a;
  double w[4] = {b * b * b, 3 * a * b * b, 3 * a * a * b, a * a * a}; /* eq. 7 */
  for (int d = 0; d < 3; d++) out[d] = w[0] * ctrl[0][d] + w[1] * ctrl[1][d] + w[2] * ctrl[2][d] + w[3] * ctrl[3][d];
}

void bezier_eval_matrix(const double ctrl[4][3], double a, double out[3]) {
  static const double M[4][4] = {{-1, 3, -3, 1}, {3, -6, 3, 0}, {-3, 3, 0, 0}, {1, 0, 0, 0}};
  double row[4] = {a * a * a, a * a, a, 1}, w[4];
  for (int j = 0; j < 4; j++) w[j] = row[0] * M[0][j] + row[1] * M[1][j] + row[2] * M[2][j] + row[3] * M[3][j];
  for (int d = 0; d < 3; d++) out[d] = w[0] * ctrl[0][d] + w[1] * ctrl[1][d] + w[2] * ctrl[2][d] + w[3] * ctrl[3][d];
}

void bezier_tangent(const double ctrl[4][3], double a, double out[3]) {
  double b = 1 - a;
  for (int d = 0; d < 3; d++)
    out[d] = 3 * b * b * (ctrl[1][d] - ctrl[0][d]) + 6 * a * b * (ctrl[2][d] - ctrl[1][d]) +
             3 * a * a * (ctrl[3][d] - ctrl[2][d]);
}

/* Point at (segment s, fraction f) of the polyline. */
static void at(const double *pts, size_t n, double s, double f, double out[3]) {
  size_t i = (size_t)s;
  if (i + 1 >= n) {
    v3_copy(out, pts + 3 * (n - 1));
    return;
  }
  for (int d = 0; d < 3; d++) out[d] = pts[3 * i + d] + f * (pts[3 * (i + 1) + d] - pts[3 * i + d]);
}

double bezier_fit_path(const double *pts, size_t n, const double *weights_in, double weights_out[4],
                       double ctrl[4][3]) {
  double len = 0;
  for (size_t i = 0; i + 1 < n; i++) len += v3_dist(pts + 3 * i, pts + 3 * i + 3);
  double w[4];
  if (weights_in) {
    for (int k = 0; k < 4; k++) w[k] = weights_in[k];
  } else {
    /* Segment and fraction where 1/3 and 2/3 of the length are reached. */
    for (int q = 0; q < 2; q++) {
      double target = len * (q + 1) / 3.0, acc = 0;
      w[2 * q] = (double)(n > 1 ? n - 2 : 0);
      w[2 * q + 1] = 1;
      for (size_t i = 0; i + 1 < n; i++) {
        double l = v3_dist(pts + 3 * i, pts + 3 * i + 3);
        if (acc + l >= target && l > 0) {
          w[2 * q] = (double)i;
          w[2 * q + 1] = (target - acc) / l;
          break;
        }
        acc += l;
      }
    }
  }
  if (weights_out)
    for (int k = 0; k < 4; k++) weights_out[k] = w[k];
  double q1[3], q2[3];
  at(pts, n, w[0], w[1], q1);
  at(pts, n, w[2], w[3], q2);
  const double *p0 = pts, *p3 = pts + 3 * (n - 1);
  /* P(1/3) = (8 P0 + 12 P1 + 6 P2 + P3) / 27 = q1 and P(2/3) = (P0 + 6 P1 +
   * 12 P2 + 8 P3) / 27 = q2: a 2x2 system in P1, P2 (determinant 108). */
  for (int d = 0; d < 3; d++) {
    double s1 = 27 * q1[d] - 8 * p0[d] - p3[d], s2 = 27 * q2[d] - p0[d] - 8 * p3[d];
    ctrl[0][d] = p0[d];
    ctrl[1][d] = (2 * s1 - s2) / 18;
    ctrl[2][d] = (2 * s2 - s1) / 18;
    ctrl[3][d] = p3[d];
  }
  return len;
}

/* Projection of q on chord a0 -> a1 of the curve: parameter and distance. */
static double chord_project(const double ctrl[4][3], double a0, double a1, const double q[3], double *dist) {
  double x0[3], x1[3], e[3], w[3];
  bezier_eval(ctrl, a0, x0);
  bezier_eval(ctrl, a1, x1);
  v3_sub(e, x1, x0);
  v3_sub(w, q, x0);
  double ee = v3_dot(e, e), t = ee > 0 ? v3_dot(w, e) / ee : 0;
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  double p[3];
  v3_copy(p, x0);
  v3_axpy(p, e, t);
  *dist = v3_dist(p, q);
  return a0 + t * (a1 - a0);
}

double bezier_nearest(const double ctrl[4][3], const double q[3], int nsamp, double *dist) {
  if (nsamp < 1) nsamp = 1;
  int best = 0;
  double bd = INFINITY;
  for (int i = 0; i <= nsamp; i++) {
    double p[3];
    bezier_eval(ctrl, (double)i / nsamp, p);
    double d = v3_dist(p, q);
    if (d < bd) {
      bd = d;
      best = i;
    }
  }
  double a = (double)best / nsamp, d = bd;
  for (int side = -1; side <= 1; side += 2) {
    int o = best + side;
    if (o < 0 || o > nsamp) continue;
    double dd,
        aa = chord_project(ctrl, (double)(side < 0 ? o : best) / nsamp, (double)(side < 0 ? best : o) / nsamp, q, &dd);
    if (dd < d) {
      d = dd;
      a = aa;
    }
  }
  if (dist) *dist = d;
  return a;
}

double bezier_length(const double ctrl[4][3], double a0, double a1, int nsamp) {
  if (nsamp < 1) nsamp = 1;
  double len = 0, prev[3], cur[3];
  bezier_eval(ctrl, a0, prev);
  for (int i = 1; i <= nsamp; i++) {
    bezier_eval(ctrl, a0 + (a1 - a0) * i / nsamp, cur);
    len += v3_dist(prev, cur);
    v3_copy(prev, cur);
  }
  return len;
}
