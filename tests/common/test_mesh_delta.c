/* SPDX-License-Identifier: Apache-2.0 */
/* Property test: keyframe plus any delta equals the exact state within the
 * quantization step; malformed deltas are refused. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "mesh_delta.h"

static double rnd(uint64_t *s) {
  *s ^= *s << 13;
  *s ^= *s >> 7;
  *s ^= *s << 17;
  return (double)(*s >> 11) / 9007199254740992.0;
}

int main(void) {
  uint64_t seed = 0x9e3779b97f4a7c15ull;
  enum { N = 500 };
  float key[3 * N], out[3 * N];
  double cur[3 * N];
  uint32_t idx[N];
  int16_t dq[3 * N];
  for (int trial = 0; trial < 300; trial++) {
    float q = (float)(1e-6 + rnd(&seed) * 1e-4);
    double amp = q * 32000.0 * rnd(&seed); /* up to the edge of the int16 range */
    double frac = rnd(&seed);              /* share of vertices that move */
    for (int i = 0; i < 3 * N; i++) key[i] = (float)(rnd(&seed) * 0.2 - 0.1);
    for (int i = 0; i < N; i++)
      for (int k = 0; k < 3; k++)
        cur[3 * i + k] = key[3 * i + k] + (rnd(&seed) < frac ? (rnd(&seed) * 2 - 1) * amp : 0);
    long n = mesh_delta_encode(key, cur, N, q, idx, dq);
    CHECK(n >= 0 && n <= N);
    if (n < 0) continue;
    verr_t err;
    CHECK(mesh_delta_apply(key, N, q, idx, (size_t)n, dq, 3 * (size_t)n, out, &err) == 0);
    /* Per coordinate: q/2 from rounding plus one float ulp of the result
     * (and of the float q itself, times the count). */
    int within = 1;
    for (int i = 0; i < 3 * N; i++) {
      double e = fabs((double)out[i] - cur[i]);
      double ulp = fabs((double)out[i]) * 1.2e-7 + 1e-12;
      if (!(e <= q * 0.5 * (1 + 1e-6) + ulp)) within = 0;
    }
    CHECK(within);
    /* Unchanged vertices are not listed. */
    for (long j = 0; j < n; j++) CHECK(dq[3 * j] | dq[3 * j + 1] | dq[3 * j + 2]);
  }
  /* Out of range asks for a keyframe instead of wrapping. */
  float k1[3] = {0, 0, 0};
  double far[3] = {1.0, 0, 0};
  CHECK(mesh_delta_encode(k1, far, 1, 1e-5f, idx, dq) == -1);
  double nan3[3] = {NAN, 0, 0};
  CHECK(mesh_delta_encode(k1, nan3, 1, 1e-5f, idx, dq) == -1);
  /* Untrusted deltas. */
  verr_t err;
  uint32_t bad_idx[2] = {3, 1};
  int16_t bad_dq[6] = {1, 1, 1, 1, 1, 1};
  float key4[12] = {0}, out4[12];
  CHECK(mesh_delta_apply(key4, 4, 1e-5f, bad_idx, 2, bad_dq, 6, out4, &err) == -1); /* not ascending */
  CHECK(strstr(err.msg, "ascending") != NULL);
  uint32_t oob[1] = {4};
  CHECK(mesh_delta_apply(key4, 4, 1e-5f, oob, 1, bad_dq, 3, out4, &err) == -1);
  CHECK(strstr(err.msg, "out of range") != NULL);
  uint32_t ok1[1] = {1};
  CHECK(mesh_delta_apply(key4, 4, 1e-5f, ok1, 1, bad_dq, 2, out4, &err) == -1); /* wrong dq length */
  CHECK(mesh_delta_apply(key4, 4, NAN, ok1, 1, bad_dq, 3, out4, &err) == -1);
  CHECK(mesh_delta_apply(key4, 4, -1.0f, ok1, 1, bad_dq, 3, out4, &err) == -1);
  CHECK(mesh_delta_apply(key4, 4, 1e-5f, ok1, 1, bad_dq, 3, out4, &err) == 0);
  CHECK_NEAR(out4[3], 1e-5, 1e-12);
  return check_report("test_mesh_delta");
}
