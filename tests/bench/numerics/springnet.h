/* SPDX-License-Identifier: Apache-2.0 */
/* springnet: a small force system written for the benchmark (S1 spring, S2
 * chain, the stiffness sweep), so every integrator of integrator.h runs on a
 * system whose forces, Jacobians and energy we know exactly.
 *
 * Point masses joined by linear springs f = k (L - L0) u with optional
 * Kelvin-Voigt damping c ((v_j - v_i) . u) u, plus gravity. Nodes with
 * inverse mass 0 are fixed. The energy is kinetic + spring + gravity with
 * the potential measured from height `z_ref` (so a swinging chain has a
 * positive E0 to divide by). */
#ifndef NUMERICS_SPRINGNET_H
#define NUMERICS_SPRINGNET_H

#include <stddef.h>
#include <stdint.h>

#include "physics/force_system.h"
#include "verr.h"

typedef struct springnet {
  size_t n, ns;
  double *x, *v, *x0;      /* 3n; x0 the initial (rest) positions */
  double *mass, *inv_mass; /* n */
  uint32_t *sp;            /* 2 ns */
  double *rest, *k, *c;    /* ns */
  double gravity[3], z_ref;
  force_system_t fs;
} springnet_t;

/* Allocates n nodes (mass 1, free, at the origin) and room for ns springs. */
int springnet_alloc(springnet_t *s, size_t n, size_t ns, verr_t *err);
void springnet_free(springnet_t *s);
/* Spring e between i and j with the current distance as rest length. */
void springnet_set_spring(springnet_t *s, size_t e, uint32_t i, uint32_t j, double k, double c);
/* Copies x into x0 and zeroes v: the state runs restart from. */
void springnet_mark_initial(springnet_t *s);
void springnet_reset(springnet_t *s);
double springnet_energy(const springnet_t *s);
/* Largest eigenvalue of M^-1 K at the current positions over the free nodes
 * (power iteration, `iters` rounds). */
double springnet_lambda_max(springnet_t *s, int iters);

#endif
