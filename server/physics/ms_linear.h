/* SPDX-License-Identifier: Apache-2.0 */
/* ms_linear: one backward-Euler linearisation of a mass_spring_t, for the
 * large-step integrator implicit_pcg (integrator.h, issue 17.3).
 *
 * ms_linear_rhs walks the springs once and at the same time
 *   - evaluates rhs = h (F(x, v) - h K v), the right-hand side of
 *     (M + h C + h^2 K) dv = rhs (F as mass_spring_forces, damping_scale
 *     included; K and C as mass_spring_stiffness_mul with the definite
 *     clamp of the geometric term),
 *   - caches each spring's 3x3 block of A' = h^2 K + h C as alpha I +
 *     beta u u^T (u the unit edge vector: 5 doubles per spring), and
 *   - writes the diagonal of A' (the Jacobi preconditioner's part beyond
 *     the mass).
 * ms_linear_mul then applies A' from the cache: no square root and no
 * divide per spring, so a conjugate-gradient iteration costs about half a
 * force evaluation.
 *
 * Storage: ms_linear_reserve allocates (construction and topology
 * changes); rhs and mul allocate nothing. Not thread-safe: one physics
 * thread owns it. */
#ifndef VISCERA_MS_LINEAR_H
#define VISCERA_MS_LINEAR_H

#include <stddef.h>

#include "physics/mass_spring.h"
#include "verr.h"

typedef struct ms_linear {
  size_t spring_cap; /* springs the cache holds */
  double *blk;       /* 5 per spring: u[3], alpha, beta */
  double home;       /* h^2 home_stiffness + h home_damping (on the diagonal) */
} ms_linear_t;

/* Makes room for nsprings (keeps a larger cache). 0, or -1 with err (OOM). */
int ms_linear_reserve(ms_linear_t *L, size_t nsprings, verr_t *err);
void ms_linear_free(ms_linear_t *L);

/* Requires L->spring_cap >= ms->nsprings. rhs and diag: 3 ms->n each.
 * Takes the AVX2 spring loop when the processor has it (run time). */
void ms_linear_rhs(ms_linear_t *L, const mass_spring_t *ms, double h, double *rhs, double *diag);
/* The same through a chosen spring loop: simd 1 the AVX2 loop (four springs
 * at a time, the scalar loop's operations in its order: rhs, diag and the
 * cache bit for bit the scalar loop's), 0 the scalar loop; simd 1 falls
 * back to scalar when the processor lacks AVX2. */
void ms_linear_rhs_path(ms_linear_t *L, const mass_spring_t *ms, double h, double *rhs, double *diag, int simd);
/* 1 when ms_linear_rhs takes the AVX2 loop on this processor. */
int ms_linear_simd_available(void);
/* out = (M + h^2 K + h C) y with the blocks cached by the last
 * ms_linear_rhs (the lumped mass folded in: one pass over the nodes). */
void ms_linear_mul(const ms_linear_t *L, const mass_spring_t *ms, const double *y, double *out);

#endif
