/* SPDX-License-Identifier: Apache-2.0 */
/* mol_linear: the molecular model's linearised step for implicit_pcg
 * (force_system_t.linearize / linear_mul, integrator.h; docs/numerics.md §10).
 *
 * Per triangle it caches, once per step, the unit edge vectors u_k, the
 * inverse lengths and the corner cosines at the step's state: everything the
 * Gauss-Newton stiffness J^T Q J of molecular_stiffness_mul (definite_jacobian)
 * needs. A product A y = (M + h^2 K + h C) y is then a pass of dot products
 * and sums per triangle with no square root and no divide (the forward-mode
 * kernel recomputes the lengths, their inverses and the cosines on every
 * product). It is the same matrix as molecular_stiffness_mul with
 * definite_jacobian set, to round-off (test_molecular checks it).
 *
 * The diagonal for the Jacobi preconditioner is the diagonal of J^T Q J
 * without the stretch-bend cross terms (exact when stretch_bend_k = 0, the
 * default; a preconditioner only needs a positive approximation).
 *
 * Not thread-safe; the owner (the model) holds one per molecular_t.
 * Allocation in mol_linear_reserve only. */
#ifndef VISCERA_MOL_LINEAR_H
#define VISCERA_MOL_LINEAR_H

#include <stddef.h>

#include "physics/molecular.h"
#include "verr.h"

typedef struct mol_linear {
  double *tri; /* MOL_LINEAR_STRIDE per triangle: u0 u1 u2, 1/l0..2, cos0..2 */
  size_t cap;  /* triangles */
  double h;    /* s, the step of the last linearize */
} mol_linear_t;

int mol_linear_reserve(mol_linear_t *L, size_t ntris, verr_t *err);
void mol_linear_free(mol_linear_t *L);

/* rhs = h (F(x, v) - h K v) at m's state, diag = diagonal of h^2 K + h C
 * (both 3n); keeps the cache for mol_linear_mul. */
void mol_linear_linearize(mol_linear_t *L, const molecular_t *m, double h, double *rhs, double *diag);

/* out = (M + h^2 K + h C) y at the last linearized state (every node). */
void mol_linear_mul(const mol_linear_t *L, const molecular_t *m, const double *y, double *out);

#endif
