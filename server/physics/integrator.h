/* SPDX-License-Identifier: Apache-2.0 */
/* integrator: time integrators for force_system_t (one sub-step each).
 *
 *   explicit_euler    x += h v; v += h M^-1 F(x, v)           (1st order, unstable undamped)
 *   symplectic_euler  v += h M^-1 F(x, v); x += h v            (1st order, h < 2/omega)
 *   verlet            velocity Verlet, kick-drift-kick         (2nd order, h < 2/omega)
 *   rk4               classical Runge-Kutta                    (4th order, h < 2.83/omega undamped)
 *   implicit_euler    one linearised backward Euler step:
 *                     (M + h C + h^2 K) dv = h (F - h K v), K = -dF/dx, CG to cg_tolerance
 *                                                              (unconditionally stable, damps)
 *   implicit_pcg      the same linearised step for one large step per
 *                     millisecond (issue 17.3): Jacobi-preconditioned CG,
 *                     warm-started from the previous step's dv (scaled by a
 *                     line search, so never worse than a cold start), at
 *                     most cg_max_iterations, the tool springs taken
 *                     implicitly after the solve (force_system_t.correct_v)
 *                                                              (1st order, damps; no energy guard)
 * Scratch buffers are allocated once in integrator_init for n nodes; a step
 * allocates nothing. Fixed nodes (inv_mass 0) never move. */
#ifndef VISCERA_INTEGRATOR_H
#define VISCERA_INTEGRATOR_H

#include <stddef.h>
#include <stdint.h>

#include "physics/force_system.h"
#include "verr.h"

typedef enum integrator_kind {
  INT_EXPLICIT_EULER,
  INT_SYMPLECTIC_EULER,
  INT_VERLET,
  INT_RK4,
  INT_IMPLICIT_EULER,
  INT_IMPLICIT_PCG,
  INT_COUNT
} integrator_kind_t;

typedef struct integrator {
  integrator_kind_t kind;
  size_t n;
  double cg_tolerance;
  int cg_max_iterations;
  int last_cg_iterations;                       /* diagnostics of the last implicit step */
  uint64_t cg_iterations_total, implicit_steps; /* implicit_pcg: since init */
  double last_cg_residual;
  double *buf[8]; /* scratch, 3n each */
} integrator_t;

/* Name as in scene files ("rk4"); -1 if unknown. */
int integrator_parse(const char *name);
const char *integrator_name(integrator_kind_t k);

int integrator_init(integrator_t *it, integrator_kind_t kind, size_t n, double cg_tolerance, int cg_max_iterations,
                    verr_t *err);
void integrator_destroy(integrator_t *it);

/* One sub-step of length h (calls s->pre_substep first). */
void integrator_substep(integrator_t *it, force_system_t *s, double h);

/* Largest stable h for the scheme given the largest eigenvalues of M^-1 K
 * (lambda_k = omega_max^2) and M^-1 C (lambda_c). INFINITY for both implicit schemes;
 * for explicit Euler the damped bound lambda_c / lambda_k. */
double integrator_stable_dt(integrator_kind_t k, double lambda_k, double lambda_c);

#define INTEGRATOR_MAX_SUBSTEPS 256

/* Sub-steps per scene step of length dt for a force-based model: `requested`
 * (solver.substeps) when > 0, 1 for the implicit schemes, otherwise
 * ceil(dt / (0.9 stable)) with stable the smaller of the scheme's bounds for
 * (lk, lc), the system's largest eigenvalues, and (lk0, lc0), its slowest
 * (home-spring) mode. Writes *substeps and *stable_dt; refuses undamped
 * explicit Euler and more than INTEGRATOR_MAX_SUBSTEPS, ending the message
 * with `advice` (what to change in the scene). */
int integrator_choose_substeps(integrator_kind_t kind, double dt, int requested, double lk, double lc, double lk0,
                               double lc0, const char *advice, int *substeps, double *stable_dt, verr_t *err);

#endif
