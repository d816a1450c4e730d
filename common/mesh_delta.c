/* SPDX-License-Identifier: Apache-2.0 */
#include "mesh_delta.h"

#include <math.h>
#include <string.h>

long mesh_delta_encode(const float *key, const double *cur, size_t nverts, float q, uint32_t *idx, int16_t *dq) {
  if (!(q > 0) || !isfinite(q)) return -1;
  double inv = 1.0 / (double)q;
  long n = 0;
  for (size_t i = 0; i < nverts; i++) {
    long d[3];
    for (int k = 0; k < 3; k++) {
      double r = nearbyint((cur[3 * i + k] - (double)key[3 * i + k]) * inv);
      if (!(fabs(r) <= MESH_DELTA_QMAX)) return -1; /* also catches NaN */
      d[k] = (long)r;
    }
    if (d[0] | d[1] | d[2]) {
      idx[n] = (uint32_t)i;
      for (int k = 0; k < 3; k++) dq[3 * n + k] = (int16_t)d[k];
      n++;
    }
  }
  return n;
}

int mesh_delta_apply(const float *key, size_t nverts, float q, const uint32_t *idx, size_t count, const int16_t *dq,
                     size_t dq_len, float *out, verr_t *err) {
  if (!(q > 0) || !isfinite(q)) return verr_set(err, "delta quant_step %g is not a positive finite number", (double)q);
  if (dq_len != 3 * count)
    return verr_set(err, "delta has %zu indices but %zu components (expected %zu)", count, dq_len, 3 * count);
  if (count > nverts) return verr_set(err, "delta lists %zu vertices but the keyframe has %zu", count, nverts);
  memcpy(out, key, nverts * 3 * sizeof(float));
  for (size_t j = 0; j < count; j++) {
    uint32_t i = idx[j];
    if (i >= nverts)
      return verr_set(err, "delta index %u at position %zu is out of range (keyframe has %zu vertices)", i, j, nverts);
    if (j > 0 && i <= idx[j - 1])
      return verr_set(err, "delta indices not ascending at position %zu (%u after %u)", j, i, idx[j - 1]);
    /* Sum in double, round once: the error is then q/2 plus one float ulp. */
    for (int k = 0; k < 3; k++) out[3 * i + k] = (float)((double)key[3 * i + k] + (double)dq[3 * j + k] * (double)q);
  }
  return 0;
}
