/* SPDX-License-Identifier: Apache-2.0 */
#include "physics/model_guard.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int model_guard_reserve(model_guard_t *g, size_t cap) {
  if (g->x && cap <= g->cap) return 0;
  /* One block: the positions in its first half, the velocities in its second. */
  size_t half = 3 * (cap ? cap : 1);
  double *x = calloc(2 * half, sizeof(double));
  if (!x) return -1;
  double *v = x + half;
  if (g->x) {
    memcpy(x, g->x, 3 * g->cap * sizeof(double));
    memcpy(v, g->v, 3 * g->cap * sizeof(double));
  }
  free(g->x);
  *g = (model_guard_t){.x = x, .v = v, .cap = cap, .n = g->n, .idx = g->idx};
  return 0;
}

void model_guard_free(model_guard_t *g) {
  free(g->x); /* v lives in the same block */
  *g = (model_guard_t){0};
}

int model_state_finite(const double *x, const double *v, size_t n, const uint32_t *idx) {
  double sum = 0;
  if (!idx) {
    /* Eight independent sums: one chain of dependent adds cost a step
     * about 5 % (a sum of 6n terms, one add latency each); NaN and
     * infinities reach the total whatever the grouping. */
    double a[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    size_t m = 3 * n, c = 0;
    for (; c + 8 <= m; c += 8)
      for (int k = 0; k < 8; k++) a[k] += x[c + (size_t)k] + v[c + (size_t)k];
    for (; c < m; c++) sum += x[c] + v[c];
    for (int k = 0; k < 8; k++) sum += a[k];
    return isfinite(sum);
  }
  for (size_t a = 0; a < n; a++) {
    size_t i = 3 * (size_t)idx[a];
    sum += x[i] + x[i + 1] + x[i + 2] + v[i] + v[i + 1] + v[i + 2];
  }
  return isfinite(sum);
}

void model_guard_save(model_guard_t *g, const double *x, const double *v, size_t n, const uint32_t *idx) {
  g->n = n;
  g->idx = idx;
  if (!idx) {
    memcpy(g->x, x, 3 * n * sizeof(double));
    memcpy(g->v, v, 3 * n * sizeof(double));
    return;
  }
  for (size_t a = 0; a < n; a++) {
    memcpy(g->x + 3 * a, x + 3 * (size_t)idx[a], 3 * sizeof(double));
    memcpy(g->v + 3 * a, v + 3 * (size_t)idx[a], 3 * sizeof(double));
  }
}

int model_guard_save_finite(model_guard_t *g, const double *x, const double *v, size_t n, const uint32_t *idx) {
  if (!model_state_finite(x, v, n, idx)) return 0;
  model_guard_save(g, x, v, n, idx);
  return 1;
}

void model_guard_restore(const model_guard_t *g, double *x, double *v) {
  if (!g->idx) {
    memcpy(x, g->x, 3 * g->n * sizeof(double));
    memcpy(v, g->v, 3 * g->n * sizeof(double));
    return;
  }
  for (size_t a = 0; a < g->n; a++) {
    memcpy(x + 3 * (size_t)g->idx[a], g->x + 3 * a, 3 * sizeof(double));
    memcpy(v + 3 * (size_t)g->idx[a], g->v + 3 * a, 3 * sizeof(double));
  }
}

int model_guard_rollback(const model_guard_t *g, double *x, double *v, uint64_t *rollbacks) {
  model_guard_restore(g, x, v);
  if (rollbacks) (*rollbacks)++;
  return -1;
}

int model_guard_check(const model_guard_t *g, double *x, double *v, size_t n, const uint32_t *idx,
                      uint64_t *rollbacks) {
  if (model_state_finite(x, v, n, idx)) return 0;
  return model_guard_rollback(g, x, v, rollbacks);
}
