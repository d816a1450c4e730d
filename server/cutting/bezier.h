/* SPDX-License-Identifier: Apache-2.0 */
/* bezier: the cubic Bezier incision curve of docs/methods.md D §2.3.2 (eq. 5-8).
 *
 * P(a) = sum_k P_k B_k,3(a), a in [0, 1], with the Bernstein polynomials
 * B_k,n(a) = n! / (k! (n-k)!) a^k (1-a)^(n-k) (eq. 6); for n = 3 (eq. 7)
 * (1-a)^3, 3a(1-a)^2, 3a^2(1-a), a^3, or in matrix form (eq. 8)
 * P(a) = [a^3 a^2 a 1] M [P0 P1 P2 P3]^T with
 * M = [-1 3 -3 1; 3 -6 3 0; -3 3 0 0; 1 0 0 0].
 *
 * The incision passes through the tool path: P0 and P3 are its first and
 * last points, and the inner control points are solved so that the curve
 * also passes through the path points at 1/3 and 2/3 of its arc length at
 * a = 1/3 and a = 2/3 (the curve passes through its end control points
 * only; interpolating two inner points keeps a bent stroke on the path
 * instead of cutting its corner).
 *
 * Pure functions, no allocation except in bezier_fit_path's caller's arrays. */
#ifndef VISCERA_BEZIER_H
#define VISCERA_BEZIER_H

#include <stddef.h>

/* B_k,n(a) by eq. 6 (k <= n <= 20); 0 outside 0 <= k <= n. */
double bezier_bernstein(int k, int n, double a);
/* Eq. 5 with n = 3 (Bernstein form): out = P(a) for control points ctrl[4][3]. */
void bezier_eval(const double ctrl[4][3], double a, double out[3]);
/* Eq. 8 (matrix form); equal to bezier_eval up to rounding. */
void bezier_eval_matrix(const double ctrl[4][3], double a, double out[3]);
/* dP/da. */
void bezier_tangent(const double ctrl[4][3], double a, double out[3]);

/* Control points of the cubic through the polyline pts[n][3] (n >= 2):
 * P0 = pts[0], P3 = pts[n-1], P(1/3) and P(2/3) = the polyline points at 1/3
 * and 2/3 of its length. With the same `weights` (which come from the first
 * polyline's arc length) a second polyline of corresponding points (the rest
 * positions) gets the matching curve: pass weights_in = NULL the first time
 * (they are computed and written to weights_out[2][2]: segment index and
 * fraction for 1/3 and 2/3), and the first call's weights_out as weights_in
 * the second time. Returns the polyline length. */
double bezier_fit_path(const double *pts, size_t n, const double *weights_in, double weights_out[4], double ctrl[4][3]);

/* Nearest point of the curve to q: samples it at nsamp + 1 parameters,
 * then projects q on the two chords beside the nearest sample. Returns the
 * parameter a; writes the distance to *dist if not NULL. */
double bezier_nearest(const double ctrl[4][3], const double q[3], int nsamp, double *dist);
/* Arc length of the curve between parameters a0 <= a1 (polyline of nsamp chords). */
double bezier_length(const double ctrl[4][3], double a0, double a1, int nsamp);

#endif
