/* SPDX-License-Identifier: Apache-2.0 */
/* ms_kidney: what the spring-loop tests (test_mass_spring_forces,
 * test_ms_linear) share: the system they check against and the measure of
 * a difference they judge by.
 *
 * ms_kidney_create: mass_spring_create_surface on the kidney asset's mesh
 * (loaded by the caller with test_mesh_load, kept alive by it while `ms`
 * lives) with fixed, soft-tissue-like parameters (0.15 kg per node, k 400
 * N/m, damping 0.8, home spring 5 N/m / 0.05, gravity -z). Returns
 * mass_spring_create_surface's result (0, or -1 with `err` set); on success
 * prints "kidney: N nodes, S springs". The caller owns `ms`
 * (mass_spring_destroy). Header-only, test code. */
#ifndef VISCERA_TEST_MS_KIDNEY_H
#define VISCERA_TEST_MS_KIDNEY_H

#include <math.h>
#include <stdio.h>

#include "mesh.h"
#include "physics/mass_spring.h"

static inline int ms_kidney_create(mass_spring_t *ms, const mesh_t *mesh, verr_t *err) {
  ms_params_t p = {.mass = 0.15,
                   .stiffness = 400,
                   .damping = 0.8,
                   .home_stiffness = 5,
                   .home_damping = 0.05,
                   .gravity = {0, 0, -9.81}};
  if (mass_spring_create_surface(ms, mesh, &p, err) != 0) return -1;
  printf("kidney: %zu nodes, %zu springs\n", ms->n, ms->nsprings);
  return 0;
}

/* max |got - want| / max |want| over `count` components (the absolute
 * difference when want is all zero); INFINITY when any of got is not
 * finite, so a non-finite result always fails a bound. */
static inline double ms_rel_diff(const double *got, const double *want, size_t count) {
  double diff = 0, scale = 0;
  for (size_t c = 0; c < count; c++) {
    if (!isfinite(got[c])) return INFINITY;
    diff = fmax(diff, fabs(got[c] - want[c]));
    scale = fmax(scale, fabs(want[c]));
  }
  return scale > 0 ? diff / scale : diff;
}

#endif
