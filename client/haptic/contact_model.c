/* SPDX-License-Identifier: Apache-2.0 */
#include "contact_model.h"

#include "vmath.h"

double contact_model_force(const contact_model_t *m, const double x[3], const double v[3], double max_force,
                           double f[3]) {
  v3_set(f, 0, 0, 0);
  if (!m->in_contact) return 0;
  double d[3];
  v3_sub(d, m->proxy, x);
  double depth = v3_dot(d, m->normal);
  if (!(depth > 0)) return 0;
  double mag = m->stiffness * depth;
  if (v) mag -= m->damping * v3_dot(v, m->normal);
  if (!(mag > 0)) return 0; /* never pull into the wall; NaN from a corrupt plane renders nothing */
  if (mag > max_force) mag = max_force;
  v3_scale(f, m->normal, mag);
  return mag;
}
