/* SPDX-License-Identifier: Apache-2.0 */
/* coupling: tool springs integrated implicitly, so that a stiff tool does
 * not enter an organ's explicit stability bound (issue 17.1).
 *
 * A tool spring acts on the tissue as f_j = -w_j k (P(x) - d) on nodes
 * j of its force set (weights w, e.g. the contact patch's), where
 * P(x) = sum_l b_l x_l + offset is the attachment point (weights b, e.g. the
 * proxy's barycentric coordinates in its triangle) and d the tool's target.
 * The forces themselves are evaluated at the sub-step's start by the
 * model's hook as before (add_surface_force); the set only records each
 * spring's structure (k, w, b) so that the integrator can treat its
 * stiffness implicitly. Symplectic Euler with the spring implicit,
 *     v' = v + h M^-1 (F(x) + f(x + h v')),  x' = x + h v',
 * is the explicit kick a = v + h M^-1 (F(x) + f(x)) followed by
 *     v' = a - h^2 k M^-1 w s,   s = b^T v' = b^T a / (1 + h^2 k b^T M^-1 w)
 * (a rank-one solve: one 3-vector and one scalar divide per spring).
 * Springs are applied one after another (Gauss-Seidel over springs). For an
 * oscillator of tissue stiffness k_t (explicit) and spring k (implicit) the
 * step is stable for h^2 k_t < 4 m + h^2 k: the spring never lowers the
 * tissue's own bound, whatever k. At rest (v' = 0) nothing changes: the
 * equilibrium, and with it the force the hand feels for a dent, is the
 * explicit spring's.
 *
 * Storage is allocated once (coupling_set_init); adding allocates nothing.
 * A spring that does not fit (more than `cap` springs or `ecap` weights in
 * one sub-step) is dropped from the set and so stays explicit; `dropped`
 * counts those. Not thread-safe: one physics thread owns a set. */
#ifndef VISCERA_COUPLING_H
#define VISCERA_COUPLING_H

#include <stddef.h>
#include <stdint.h>

#include "verr.h"

typedef struct coupling_spring {
  double k;        /* N/m */
  uint32_t w0, nw; /* force weights: entries [w0, w0 + nw) */
  uint32_t b0, nb; /* attachment weights: entries [b0, b0 + nb) */
} coupling_spring_t;

typedef struct coupling_set {
  size_t n, cap;   /* springs */
  size_t ne, ecap; /* weight entries */
  coupling_spring_t *s;
  uint32_t *node; /* ecap */
  double *wt;     /* ecap */
  int open;       /* 1 between begin and end */
  uint64_t dropped;
} coupling_set_t;

/* 0, or -1 with err (OOM). */
int coupling_set_init(coupling_set_t *cs, size_t cap, size_t ecap, verr_t *err);
void coupling_set_free(coupling_set_t *cs);
/* Empties the set (before each sub-step's hook). */
static inline void coupling_set_clear(coupling_set_t *cs) {
  cs->n = cs->ne = 0;
  cs->open = 0;
}

/* Building one spring: begin(k), then every force weight (push_w), then
 * every attachment weight (push_b), then end. Weights of nodes that are
 * fixed need not be left out (the solve masks them). */
void coupling_begin(coupling_set_t *cs, double k);
void coupling_push_w(coupling_set_t *cs, uint32_t node, double w);
void coupling_push_b(coupling_set_t *cs, uint32_t node, double b);
void coupling_end(coupling_set_t *cs);
/* begin, push, end in one, for a model whose surface vertices are its n
 * nodes (model.h add_surface_coupling's arguments): entries with an index
 * >= n are left out. */
void coupling_add(coupling_set_t *cs, double k, size_t n, size_t nw, const uint32_t *wi, const double *w, size_t nb,
                  const uint32_t *bi, const double *b);

/* The implicit correction after the explicit kick (file comment): v (3 per
 * node) holds a on entry and v' on return; inv_mass per node (0: fixed). */
void coupling_set_apply(const coupling_set_t *cs, const double *inv_mass, double h, double *v);

/* For a position-based solver (pbd.h), after coupling_set_apply on the
 * sub-step's velocity: x = x_old + h v on the nodes of every spring's force
 * set (the nodes the solve moved; fixed ones left). */
void coupling_set_drift(const coupling_set_t *cs, const double *inv_mass, double h, const double *x_old,
                        const double *v, double *x);

#endif
