#include "passivity.h"

#include <math.h>
#include <string.h>

#include "vmath.h"

void passivity_init(passivity_t *p, double period_s, double max_damping) {
  memset(p, 0, sizeof *p);
  p->period_s = period_s;
  p->max_damping = max_damping;
}

double passivity_control(passivity_t *p, const double v[3], double max_force, double f[3]) {
  double vv = v3_dot(v, v);
  double e_pred = p->energy + v3_dot(f, v) * p->period_s;
  if (!(e_pred > 0) || !(vv > 1e-12) || !isfinite(vv)) return 0;
  double alpha = e_pred / (p->period_s * vv);
  if (alpha > p->max_damping) alpha = p->max_damping;
  double g[3];
  v3_copy(g, f);
  v3_axpy(g, v, -alpha);
  double mag = v3_norm(g);
  if (mag > max_force && mag > 0) v3_scale(g, g, max_force / mag);
  p->dissipated += (v3_dot(f, v) - v3_dot(g, v)) * p->period_s;
  p->active_ticks++;
  v3_copy(f, g);
  return alpha;
}

void passivity_observe(passivity_t *p, const double f[3], const double v[3]) {
  double de = v3_dot(f, v) * p->period_s;
  if (!isfinite(de)) return;
  p->energy += de;
  if (p->energy > p->energy_max) p->energy_max = p->energy;
}
