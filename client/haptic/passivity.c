/* SPDX-License-Identifier: Apache-2.0 */
#include "passivity.h"

#include <math.h>
#include <string.h>

#include "vmath.h"

void passivity_init(passivity_t *p, double period_s, double max_damping) {
  memset(p, 0, sizeof *p);
  p->period_s = period_s;
  p->max_damping = max_damping;
}

double passivity_control(passivity_t *p, const double v[3], double max_force, double reserve, double f[3]) {
  double vv = v3_dot(v, v), fv = v3_dot(f, v);
  double e_pred = p->energy + fv * p->period_s + reserve;
  if (!(e_pred > 0) || !(fv > 0) || !(vv > 1e-12) || !isfinite(vv)) return 0;
  /* The damper alpha v, applied along the force's own line: the force is
   * scaled down by s so that its power f.v drops by alpha |v|^2. A damper
   * may not reverse the force (pull the hand into a wall it pushes out of),
   * so s stops at 0; the device's damping limit bounds alpha. */
  double alpha = e_pred / (p->period_s * vv);
  if (alpha > p->max_damping) alpha = p->max_damping;
  double s = 1.0 - alpha * vv / fv;
  if (s < 0) s = 0;
  double g[3];
  v3_scale(g, f, s);
  double mag = v3_norm(g);
  if (mag > max_force && mag > 0) v3_scale(g, g, max_force / mag);
  p->dissipated += (fv - v3_dot(g, v)) * p->period_s;
  p->active_ticks++;
  v3_copy(f, g);
  return (1.0 - s) * fv / vv;
}

void passivity_observe(passivity_t *p, const double f[3], const double dx[3]) {
  double de = v3_dot(f, dx);
  if (!isfinite(de)) return;
  p->energy += de;
  if (p->energy > p->energy_max) p->energy_max = p->energy;
}
