/* SPDX-License-Identifier: Apache-2.0 */
/* force_system: what a force-based model (mass-spring on surfaces or
 * tetrahedra, molecular) exposes to the integrators in integrator.h.
 *
 * State: positions x and velocities v (3n each), lumped masses, fixed nodes
 * (inv_mass 0). forces() evaluates all internal and external forces at a
 * state; stiffness_mul() applies the force Jacobians -dF/dx (K) and -dF/dv
 * (C) to a vector, for the implicit integrator's conjugate gradient. */
#ifndef VISCERA_FORCE_SYSTEM_H
#define VISCERA_FORCE_SYSTEM_H

#include <stddef.h>

typedef struct force_system force_system_t;

struct force_system {
  size_t n;
  double *x, *v;          /* 3n, owned by the model */
  const double *mass;     /* n */
  const double *inv_mass; /* n, 0 = fixed */
  /* f = F(x, v) including external forces for the current sub-step. */
  void (*forces)(force_system_t *s, const double *x, const double *v, double *f);
  /* out = (a K(x) + b C(x)) y, K = -dF/dx, C = -dF/dv, evaluated at x. May be
   * NULL: the implicit integrator is then unavailable for the model. */
  void (*stiffness_mul)(force_system_t *s, const double *x, double a, double b, const double *y, double *out);
  /* Called before EVERY force evaluation (Verlet: 2 per sub-step, RK4: 4),
   * so it must set the external forces (contact hooks), not add to them;
   * may be NULL. */
  void (*pre_substep)(force_system_t *s);
  /* Optional (NULL: none), symplectic Euler and implicit_pcg: called between the kick
   * (s->v holds v + h M^-1 F) and the drift, to correct the velocities for
   * forces integrated implicitly (physics/coupling.h). */
  void (*correct_v)(force_system_t *s, double h);
  /* Optional (NULL: implicit_pcg falls back to forces and stiffness_mul),
   * implicit_pcg only. linearize writes rhs = h (F(x, v) - h K v) at the
   * current state and diag, the diagonal of A' = h^2 K + h C, and keeps
   * what linear_mul needs to apply A = M + A' (out = A y, every node; the
   * integrator masks the fixed ones) until the next call. */
  void (*linearize)(force_system_t *s, double h, double *rhs, double *diag);
  void (*linear_mul)(force_system_t *s, const double *y, double *out);
  void *ctx; /* the owning model */
};

#endif
