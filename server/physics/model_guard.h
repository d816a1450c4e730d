/* SPDX-License-Identifier: Apache-2.0 */
/* model_guard: the one roll-back and non-finite guard every model's step
 * goes through (mass_spring, molecular, pbd/xpbd, vertex_based, adaptive).
 *
 * A step saves the state it starts from (model_guard_save, or
 * model_guard_save_finite: only a finite state, so a state made non-finite
 * from outside between steps rolls back to the last finite one), runs its
 * sub-steps, and ends with model_guard_check: when x and v are not finite
 * it puts the saved state back, counts the rollback and returns -1.
 * Finiteness is one sum over the coordinates (NaN or Inf anywhere, or an
 * overflow, makes it non-finite): cheaper than classifying each value.
 *
 * The saved nodes are nodes 0..n-1 (idx NULL) or the list idx[0..n)
 * (vertex_based saves its active nodes only, so a step costs what the live
 * neighbourhood costs). What a model does beyond the restore follows the
 * check in the model (pbd clears its multipliers and sends nodes that were
 * already non-finite home; vertex_based retires nodes activated during the
 * failed step; adaptive leaves its topology alone).
 *
 * Buffers are allocated by model_guard_reserve (at create, and when a
 * topology change grows the node capacity); save, check and restore
 * allocate nothing. Not thread-safe: one physics thread owns a model. */
#ifndef VISCERA_MODEL_GUARD_H
#define VISCERA_MODEL_GUARD_H

#include <stddef.h>
#include <stdint.h>

typedef struct model_guard {
  double *x, *v;       /* 3 cap each (one block): the saved positions and velocities, in save order */
  size_t cap;          /* nodes the buffers hold */
  size_t n;            /* nodes saved by the last save */
  const uint32_t *idx; /* the saved nodes, or NULL: nodes 0..n-1 */
} model_guard_t;

/* Room for cap nodes, zero-filled when new; keeps what was saved. 0, or -1
 * (out of memory: the guard unchanged). */
int model_guard_reserve(model_guard_t *g, size_t cap);
void model_guard_free(model_guard_t *g);

/* 1 when x and v of the nodes (0..n-1, or idx[0..n)) are all finite. */
int model_state_finite(const double *x, const double *v, size_t n, const uint32_t *idx);

/* Saves x and v of the nodes (n <= cap). idx must stay valid and keep its
 * first n entries until the check. */
void model_guard_save(model_guard_t *g, const double *x, const double *v, size_t n, const uint32_t *idx);
/* The same, only when they are finite; returns whether it saved. */
int model_guard_save_finite(model_guard_t *g, const double *x, const double *v, size_t n, const uint32_t *idx);

/* Puts the saved nodes back into x and v. */
void model_guard_restore(const model_guard_t *g, double *x, double *v);

/* The end of a step: 0 when x and v over the nodes (0..n-1, or idx[0..n):
 * may be more than were saved) are finite; otherwise restores the saved
 * nodes, increments *rollbacks (when not NULL) and returns -1. */
int model_guard_check(const model_guard_t *g, double *x, double *v, size_t n, const uint32_t *idx, uint64_t *rollbacks);
/* Restores and counts unconditionally (a step that could not run); -1. */
int model_guard_rollback(const model_guard_t *g, double *x, double *v, uint64_t *rollbacks);

#endif
