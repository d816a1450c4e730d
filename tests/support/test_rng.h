/* SPDX-License-Identifier: Apache-2.0 */
/* test_rng: the pseudo-random numbers randomized tests and benchmarks draw
 * (splitmix64, and an older 32-bit LCG): the same sequence on every machine and run for a given
 * seed, so a failing randomized case reproduces. The caller owns the state
 * (any value seeds it). Header-only. */
#ifndef VISCERA_TEST_RNG_H
#define VISCERA_TEST_RNG_H

#include <stdint.h>

/* Uniform in [0, 1), 53 random bits; advances *state. */
static inline double test_rng_uniform(uint64_t *state) {
  uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  z ^= z >> 31;
  return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

/* Uniform in [0, 1), 24 bits, from the 32-bit linear congruential
 * generator (Numerical Recipes' 1664525, 1013904223) that the older
 * randomized cases were written with: the stability tests' perturbations
 * (stab_util.h) and the random incisions of tests/stability/cut_scenario.h
 * keep exactly their sequences with it. Advances *state. */
static inline double test_rng_lcg(unsigned *state) {
  *state = *state * 1664525u + 1013904223u;
  return (double)(*state >> 8) / 16777216.0;
}

#endif
