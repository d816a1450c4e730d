/* SPDX-License-Identifier: Apache-2.0 */
#include "passivity.h"

#include <math.h>
#include <string.h>

#include "vmath.h"

void passivity_init(passivity_t *p, double period_s) {
  memset(p, 0, sizeof *p);
  p->period_s = period_s;
}

/* The release of m in steps of r ends within this many ticks (m <= a
 * device's force, r >= 1 mN): the sum is bounded. */
#define PASSIVITY_MAX_RELEASE_TICKS 10000

#define PASSIVITY_ROUNDING (1.0 + 1e-6)
/* N: the controller renders nothing rather than less than this. */
#define PASSIVITY_MIN_FORCE 1e-4

double passivity_owed(double m, double u, double a, double tick_s, double hold_s, double release_step, double u_floor) {
  if (!(m > 0) || !(release_step > 0) || !isfinite(u) || !isfinite(a)) return 0;
  if (!(u_floor > 0)) u_floor = 0;
  if (hold_s < tick_s) hold_s = tick_s;
  double ap = a > 0 ? a : 0, u0 = u + ap * hold_s, w = u0 > 0 ? m * u0 * hold_s : 0;
  if (w < m * u_floor * tick_s) w = m * u_floor * tick_s; /* this tick, at least at the floor */
  for (int k = 1; k < PASSIVITY_MAX_RELEASE_TICKS; k++) {
    double mk = m - k * release_step;
    if (mk <= 0) break;
    double uk = u + ap * (hold_s + k * tick_s);
    if (uk < u_floor) uk = u_floor;
    if (uk > 0) w += mk * uk * tick_s;
  }
  return w;
}

double passivity_control(passivity_t *p, const double v[3], const double a[3], double tick_s, double hold_s,
                         double release_step, double f[3]) {
  double m = v3_norm(f);
  if (!(m > 0) || !isfinite(m)) return 1;
  double d[3];
  v3_scale(d, f, 1.0 / m);
  double u = v3_dot(v, d), acc = a ? v3_dot(a, d) : 0;
  if (tick_s < p->period_s) tick_s = p->period_s;
  /* Within the budget with a relative margin for the rounding of the sums
   * (W is a sum of up to m / r products; E of every tick's). */
  double owed = passivity_owed(m, u, acc, tick_s, hold_s, release_step, p->release_floor) * PASSIVITY_ROUNDING;
  double e = p->energy - p->credit; /* <= 0: within the credited budget */
  if (e + owed <= 0) return 1;
  /* W grows with m: the largest m' in [0, m] within the budget, by
   * bisection (60 halvings reach the double's resolution). */
  double lo = 0, hi = m;
  if (e < 0)
    for (int i = 0; i < 60; i++) {
      double mid = 0.5 * (lo + hi);
      if (e + passivity_owed(mid, u, acc, tick_s, hold_s, release_step, p->release_floor) * PASSIVITY_ROUNDING <= 0)
        lo = mid;
      else
        hi = mid;
    }
  /* A force below any device's resolution buys nothing and, held over a
   * tick longer than budgeted, would still do (a little) work. */
  if (lo < PASSIVITY_MIN_FORCE) lo = 0;
  double s = lo / m;
  p->dissipated +=
      (owed - passivity_owed(lo, u, acc, tick_s, hold_s, release_step, p->release_floor) * PASSIVITY_ROUNDING) /
      PASSIVITY_ROUNDING;
  p->active_ticks++;
  v3_scale(f, f, s);
  return s;
}

void passivity_observe(passivity_t *p, const double f[3], const double dx[3]) {
  double de = v3_dot(f, dx);
  if (!isfinite(de)) return;
  p->energy += de;
  if (p->energy > p->energy_max) p->energy_max = p->energy;
  if (p->energy - p->credit > p->excess_max) p->excess_max = p->energy - p->credit;
  if (p->episode && p->ep_start - p->energy > p->ep_banked) p->ep_banked = p->ep_start - p->energy;
}

void passivity_episode_open(passivity_t *p) {
  if (p->episode) return;
  p->episode = 1;
  p->ep_start = p->energy;
  p->ep_banked = 0;
  p->ep_credit = 0;
}

void passivity_episode_close(passivity_t *p) { p->episode = 0; }

double passivity_spring_energy(double f, double k) {
  if (!(k > 0) || !isfinite(f) || !isfinite(k)) return 0;
  return f * f / (2 * k);
}

double passivity_credit(passivity_t *p, double stored_j) {
  if (!p->episode || !isfinite(stored_j)) return 0;
  double c = stored_j - p->ep_banked;
  if (!(c > p->ep_credit)) return 0;
  double raise = c - p->ep_credit;
  p->ep_credit = c;
  p->credit += raise;
  return raise;
}
