/* SPDX-License-Identifier: Apache-2.0 */
#include "runtime/organ_sleep.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int reserve(organ_sleep_t *s, size_t n) {
  if (n <= s->cap && s->prev) return 0;
  size_t cap = n ? n : 1;
  double *p = realloc(s->prev, 3 * cap * sizeof *p);
  if (!p) return -1;
  s->prev = p;
  s->cap = cap;
  return 0;
}

int organ_sleep_init(organ_sleep_t *s, size_t nsurf, verr_t *err) {
  memset(s, 0, sizeof *s);
  if (reserve(s, nsurf)) return verr_set(err, "organ sleep: out of memory for %zu vertices", nsurf);
  return 0;
}

void organ_sleep_free(organ_sleep_t *s) {
  free(s->prev);
  memset(s, 0, sizeof *s);
}

void organ_sleep_wake(organ_sleep_t *s) {
  if (s->asleep) s->wakes++;
  s->asleep = 0;
  s->still = 0;
  /* The surface has not moved while asleep: prev still equals it, so the
   * first step after waking is measured against the right positions. */
}

int organ_sleep_observe_listed(organ_sleep_t *s, const double *x, size_t n, const uint32_t *idx, size_t nidx,
                               double max_move, uint32_t need, int disturbed) {
  if (n != s->n || !s->have_prev) {
    s->have_prev = 0;
    s->still = 0;
    if (reserve(s, n)) return -1;
    memcpy(s->prev, x, 3 * n * sizeof *x);
    s->n = n;
    s->have_prev = 1;
    return 0;
  }
  /* Compare squared distances: no sqrt per vertex. `!(d <= lim)` makes
   * NaN count as moving. Only the listed vertices can differ from prev
   * (every vertex when idx is NULL); the rest are equal, so still. */
  double lim = max_move * max_move;
  int still = !disturbed;
  size_t m = idx ? nidx : n;
  for (size_t a = 0; a < m && still; a++) {
    const size_t i = idx ? idx[a] : a;
    if (i >= n) continue;
    const double *p = x + 3 * i, *b = s->prev + 3 * i;
    double d0 = p[0] - b[0], d1 = p[1] - b[1], d2 = p[2] - b[2];
    if (!(d0 * d0 + d1 * d1 + d2 * d2 <= lim)) still = 0;
  }
  if (idx) {
    for (size_t a = 0; a < nidx; a++)
      if (idx[a] < n) memcpy(s->prev + 3 * (size_t)idx[a], x + 3 * (size_t)idx[a], 3 * sizeof *x);
  } else {
    memcpy(s->prev, x, 3 * n * sizeof *x);
  }
  s->still = still ? s->still + 1 : 0;
  if (s->still >= need && need > 0 && !s->asleep) {
    s->asleep = 1;
    s->sleeps++;
    return 1;
  }
  return 0;
}

int organ_sleep_observe(organ_sleep_t *s, const double *x, size_t n, double max_move, uint32_t need, int disturbed) {
  return organ_sleep_observe_listed(s, x, n, NULL, 0, max_move, need, disturbed);
}

int organ_sleep_box_near(const double lo[3], const double hi[3], const double p0[3], const double p1[3], double reach) {
  /* Anything not finite: near, awake is the safe answer. */
  for (int k = 0; k < 3; k++)
    if (!isfinite(p0[k]) || !isfinite(p1[k]) || isnan(lo[k]) || isnan(hi[k]) || !isfinite(reach)) return 1;
  for (int k = 0; k < 3; k++) {
    double a = fmin(p0[k], p1[k]) - reach, b = fmax(p0[k], p1[k]) + reach;
    if (b < lo[k] || a > hi[k]) return 0;
  }
  return 1;
}
