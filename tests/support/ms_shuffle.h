/* SPDX-License-Identifier: Apache-2.0 */
/* ms_shuffle: breaks up a mass-spring system's spring order for the tests
 * that check the AVX2 loops against the scalar ones for any order
 * (test_mass_spring_forces, test_ms_linear): the springs shuffled
 * (Fisher-Yates, each k_scale factor moved with its spring; k_scale must be
 * set) and every third spring's ends swapped, so the runs of equal i the
 * loops exploit are broken up. The caller calls
 * mass_spring_springs_changed afterwards. Header-only, test code. */
#ifndef VISCERA_TEST_MS_SHUFFLE_H
#define VISCERA_TEST_MS_SHUFFLE_H

#include <stdint.h>

#include "physics/mass_spring.h"
#include "test_rng.h"

static inline void ms_shuffle_springs(mass_spring_t *ms, uint64_t *rng) {
  size_t ns = ms->nsprings;
  for (size_t s = ns - 1; s > 0; s--) {
    size_t r = (size_t)(test_rng_uniform(rng) * (double)(s + 1));
    ms_spring_t t = ms->springs[s];
    ms->springs[s] = ms->springs[r];
    ms->springs[r] = t;
    double k = ms->k_scale[s];
    ms->k_scale[s] = ms->k_scale[r];
    ms->k_scale[r] = k;
  }
  for (size_t s = 0; s < ns; s += 3) {
    uint32_t t = ms->springs[s].i;
    ms->springs[s].i = ms->springs[s].j;
    ms->springs[s].j = t;
  }
}

#endif
