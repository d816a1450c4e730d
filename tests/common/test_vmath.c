/* SPDX-License-Identifier: Apache-2.0 */
/* Closest point on triangle and segment-triangle intersection against
 * hand-computed answers and brute-force sampling. */
#include <stdlib.h>

#include "check.h"
#include "vmath.h"

static double rnd(unsigned *s) {
  *s = *s * 1103515245u + 12345u;
  return ((*s >> 8) & 0xffff) / 65535.0;
}

int main(void) {
  double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0}, out[3], bary[3];
  /* Above the interior: projects straight down. */
  tri_closest_point((double[]){0.25, 0.25, 2}, a, b, c, out, bary);
  CHECK_NEAR(out[0], 0.25, 1e-12);
  CHECK_NEAR(out[1], 0.25, 1e-12);
  CHECK_NEAR(out[2], 0, 1e-12);
  CHECK_NEAR(bary[0] + bary[1] + bary[2], 1, 1e-12);
  /* Beyond vertex b and beyond edge bc. */
  tri_closest_point((double[]){3, -1, 0}, a, b, c, out, bary);
  CHECK_NEAR(out[0], 1, 1e-12);
  CHECK_NEAR(bary[1], 1, 1e-12);
  tri_closest_point((double[]){1, 1, 0}, a, b, c, out, bary);
  CHECK_NEAR(out[0], 0.5, 1e-12);
  CHECK_NEAR(out[1], 0.5, 1e-12);
  /* Degenerate (collinear) triangle stays finite. */
  double d1[3] = {2, 0, 0};
  tri_closest_point((double[]){0.5, 1, 0}, a, b, d1, out, bary);
  CHECK(v3_isfinite(out) && v3_isfinite(bary));
  /* Random points: no sampled point of the triangle is closer. */
  unsigned seed = 7;
  for (int it = 0; it < 200; it++) {
    double p[3] = {rnd(&seed) * 4 - 2, rnd(&seed) * 4 - 2, rnd(&seed) * 2 - 1};
    tri_closest_point(p, a, b, c, out, bary);
    double best = v3_dist(p, out);
    for (int i = 0; i <= 20; i++)
      for (int j = 0; i + j <= 20; j++) {
        double q[3] = {i / 20.0, j / 20.0, 0};
        if (v3_dist(p, q) < best - 1e-9) {
          CHECK(0 && "sampled point closer than tri_closest_point");
          i = 21;
          break;
        }
      }
  }
  /* Segment through the triangle, parallel, and missing. */
  double t;
  CHECK(seg_tri_intersect((double[]){0.2, 0.2, 1}, (double[]){0.2, 0.2, -1}, a, b, c, &t, bary) == 1);
  CHECK_NEAR(t, 0.5, 1e-12);
  CHECK_NEAR(bary[1], 0.2, 1e-12);
  CHECK(seg_tri_intersect((double[]){0.2, 0.2, 1}, (double[]){0.3, 0.2, 1}, a, b, c, &t, bary) == 0);
  CHECK(seg_tri_intersect((double[]){2, 2, 1}, (double[]){2, 2, -1}, a, b, c, &t, bary) == 0);
  CHECK(seg_tri_intersect((double[]){0.2, 0.2, 1}, (double[]){0.2, 0.2, 0.5}, a, b, c, &t, bary) == 0);
  /* Normalising a zero vector leaves zero, not NaN. */
  double z[3] = {0, 0, 0};
  v3_normalize(z);
  CHECK(v3_isfinite(z) && z[0] == 0);
  return check_report("test_vmath");
}
