/* SPDX-License-Identifier: Apache-2.0 */
/* ms_kidney: the mass-spring system the spring-loop tests check against
 * (test_mass_spring_forces, test_ms_linear): mass_spring_create_surface on
 * the kidney asset's mesh (loaded by the caller with test_mesh_load, kept
 * alive by it while `ms` lives) with fixed, soft-tissue-like parameters
 * (0.15 kg per node, k 400 N/m, damping 0.8, home spring 5 N/m / 0.05,
 * gravity -z). Returns mass_spring_create_surface's result (0, or -1 with
 * `err` set); on success prints "kidney: N nodes, S springs". The caller
 * owns `ms` (mass_spring_destroy). Header-only, test code. */
#ifndef VISCERA_TEST_MS_KIDNEY_H
#define VISCERA_TEST_MS_KIDNEY_H

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

#endif
