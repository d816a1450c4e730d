/* SPDX-License-Identifier: Apache-2.0 */
/* vertex_based: vertex-based local deformation (docs/methods.md B ch. 4).
 *
 * The touched node and its first and second rings of neighbours are moved
 * directly along the applied force by the slope-intercept rule (eq. 4.2-4.4,
 * intercepts b = 0):
 *     P = P_home + m_k F / k_home,   k = 1 touched node, 2 ring 1, 3 ring 2,
 * with m1 > m2 > m3 > 0 dimensionless (the thesis' slopes are in m/N; ours are
 * the thesis' slope times k_home, so m1 = 1 puts the touched node exactly where
 * its home spring balances F). Home springs to the fixed nodes (eq. 4.11:
 * f = k_s (x1 - x2) + k_d (v1 - v2), x1 the fixed node) restore the shape when
 * the tool leaves.
 *
 * The commanded position is not imposed in one jump: with the haptic proxy in
 * the loop the force depends on the surface position, and a jump of gain
 * m1 K_tool / k_home (10 with the default materials) makes the loop chatter.
 * Instead, during contact the home spring's anchor moves from the fixed node
 * to the commanded position P, and each node obeys
 *     m a = k_home (P - x) - c_home v      (P = P_home when untouched),
 * integrated by backward Euler per node (each node is an independent linear
 * oscillator, so the implicit step is a closed-form division). At rest under a
 * steady force every node sits exactly at eq. 4.2-4.4; after release it
 * returns by eq. 4.11.
 *
 * Cost: rings are precomputed once (CSR, docs/methods.md B §4.2.1 preprocessing); a
 * sub-step visits only the touched node's two rings plus the nodes still
 * moving back home (the active list), never the whole mesh. Nothing is
 * allocated after vb_create. Not thread-safe: one physics thread owns it. */
#ifndef VISCERA_VERTEX_BASED_H
#define VISCERA_VERTEX_BASED_H

#include <stddef.h>
#include <stdint.h>

#include "mesh.h"
#include "physics/model_guard.h"
#include "verr.h"

typedef struct vb_params {
  double mass;           /* kg, total, lumped equally over the vertices */
  double home_stiffness; /* N/m per vertex, > 0 (sets the indentation scale F / k_home) */
  double home_damping;   /* N s/m per vertex, >= 0 */
  double slope[3];       /* m1 > m2 > m3 > 0 */
  double tool_stiffness; /* N/m, stiffest tool spring acting on the surface (sub-step bound) */
} vb_params_t;

typedef struct vb {
  size_t n;
  vb_params_t p;
  double node_mass; /* kg, p.mass / n */
  double *x, *v;    /* 3n */
  double *x_rest;   /* 3n, the fixed nodes (home positions) */
  uint8_t *fixed;   /* n, never moves */
  /* Rings (CSR): ring 1 of i is r1_idx[r1_off[i] .. r1_off[i+1]), sorted;
   * ring 2 (graph distance exactly 2) likewise. */
  uint32_t *r1_off, *r1_idx, *r2_off, *r2_idx;
  /* Active list: every node not exactly at home with zero velocity. */
  uint32_t *active;
  size_t nactive;
  uint8_t *is_active;
  model_guard_t guard; /* the active nodes at step start, for rollback (physics/model_guard.h) */
  /* Contact accumulated by vb_add_force for the current sub-step. */
  double f_sum[3];
  uint32_t touched; /* node with the largest single applied force, UINT32_MAX if none */
  double touched_mag;
  /* Tool stiffness declared by vb_add_coupling for the current sub-step
   * (N/m, summed): the touched node takes it implicitly (vertex_based.c). */
  double coupling_k;
  /* Statistics of the last vb_step. */
  uint32_t last_touched;    /* touched node of the last sub-step that had contact, or UINT32_MAX */
  size_t last_node_updates; /* node integrations summed over the sub-steps */
  size_t max_active;        /* largest active list seen since create */
  double eps_x, eps_v;      /* below both a node is snapped home and leaves the active list */
} vb_t;

/* Builds rings from the triangles of `surface` (vertex positions are the home
 * positions). Returns 0, or -1 with err: slopes not m1 > m2 > m3 > 0,
 * k_home <= 0, mass <= 0, invalid mesh, OOM. */
int vb_create(vb_t *vb, const mesh_t *surface, const vb_params_t *p, verr_t *err);
void vb_destroy(vb_t *vb);

/* Fixes every vertex whose home z is below z. Returns how many. */
size_t vb_fix_below(vb_t *vb, double z);

/* Ring accessors. */
static inline const uint32_t *vb_ring1(const vb_t *vb, uint32_t i, size_t *count) {
  *count = vb->r1_off[i + 1] - vb->r1_off[i];
  return vb->r1_idx + vb->r1_off[i];
}
static inline const uint32_t *vb_ring2(const vb_t *vb, uint32_t i, size_t *count) {
  *count = vb->r2_off[i + 1] - vb->r2_off[i];
  return vb->r2_idx + vb->r2_off[i];
}

/* Largest stable sub-step with the tool spring in the loop (explicit in the
 * force, implicit in the home spring): h^2 (g - k) - 2 h c - 4 m < 0 with
 * g = m1 K_tool (the worst loop gain: the proxy moves at most as much as the
 * touched node). INFINITY when g <= k. */
double vb_stable_dt(const vb_t *vb);

/* Force f (N) at node i for the current sub-step (cleared by every sub-step).
 * The node receiving the largest single force is the touched node; the sum
 * of all forces of the sub-step is the F of eq. 4.2-4.4. */
/* Declares that the forces added this sub-step include a tool spring of
 * stiffness k (N/m) (issue 17.1). The touched node's backward-Euler update
 * then takes slope_m1 * k in its denominator: the loop force -> indentation
 * -> force is implicit, so the step is stable for any tool stiffness; at
 * rest nothing changes (same equilibrium, same felt stiffness). Create
 * with p.tool_stiffness 0 when every tool spring is declared. */
void vb_add_coupling(vb_t *vb, double k);
void vb_add_force(vb_t *vb, uint32_t i, const double f[3]);

typedef void (*vb_pre_fn)(void *ctx);

/* Advances by h in `substeps` equal sub-steps; pre(ctx), if set, runs before
 * each and may call vb_add_force. On a non-finite state restores the state
 * from before the call and returns -1; otherwise 0. */
int vb_step(vb_t *vb, double h, int substeps, vb_pre_fn pre, void *ctx);

/* Kinetic + home-spring energy, J (only active nodes contribute). */
double vb_energy(const vb_t *vb);
/* Largest |L/L0 - 1| over edges with an active endpoint: the max edge strain
 * of the whole mesh, since edges between resting nodes are unstrained. */
double vb_max_edge_strain(const vb_t *vb);

/* The scene model "vertex_based" (model_vertex_based.c): material slopes,
 * home springs and mass from the organ, sub-steps from vb_stable_dt with the
 * tool stiffness (or solver.substeps). NULL with err naming the organ. */
struct model;
struct model_params;
struct model *model_vertex_based_create(const struct model_params *p, verr_t *err);
/* The model's state (rings, active list, statistics); NULL if m is not a
 * vertex_based model. */
vb_t *model_vertex_based_state(struct model *m);

#endif
