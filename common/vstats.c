/* SPDX-License-Identifier: Apache-2.0 */
#include "vstats.h"

#include <stdlib.h>

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double pct(const double *v, size_t n, double p) {
  size_t i = (size_t)(p * (double)(n - 1) + 0.5);
  return v[i < n ? i : n - 1];
}

vstats_summary_t vstats_summarise(double *v, size_t n) {
  vstats_summary_t s = {0};
  if (n == 0) return s;
  qsort(v, n, sizeof *v, cmp_double);
  double sum = 0;
  for (size_t i = 0; i < n; i++) sum += v[i];
  s.n = n;
  s.min = v[0];
  s.max = v[n - 1];
  s.mean = sum / (double)n;
  s.median = pct(v, n, 0.5);
  s.p95 = pct(v, n, 0.95);
  s.p99 = pct(v, n, 0.99);
  return s;
}
