/* SPDX-License-Identifier: Apache-2.0 */
/* ms_regions: regional sleeping for the explicit mass-spring step (issue 17):
 * only the nodes that move, and their springs, are integrated.
 *
 * Why: in an explicit scheme a disturbance travels at most one spring per
 * sub-step, and under a local press most of a large organ is at rest (the
 * home springs, as stiff as the edges, make the static response decay
 * within a few rings of the probe). Evaluating and integrating the still
 * part costs most of the step on a 23.5k-vertex liver for nothing.
 *
 * The rule, per node (one sub-step of symplectic Euler at a time):
 * - An awake node falls asleep after `need` consecutive sub-steps in which
 *   its speed stayed below speed_sleep, its net force below force_sleep
 *   (half of force_wake) and no external force or tool spring touched it.
 *   Asleep, its velocity is set to 0 and its position is kept bit for bit:
 *   it is not integrated and the springs between two sleeping nodes are
 *   not evaluated (their last force rows stay valid: neither end moves).
 * - A sleeping node with an awake neighbour (the frontier) has its net
 *   force evaluated every sub-step (its springs to awake nodes are live);
 *   above force_wake it wakes and is integrated from that sub-step on. A
 *   sleeping node without an awake neighbour feels a constant force, below
 *   force_wake when it was last evaluated (the hysteresis: no chatter).
 * - An external force or a tool spring on a node wakes it at once (before
 *   the forces of the sub-step); a topology change, a rollback, a change of
 *   the material or thresholds wakes every node (ms_regions_build).
 * So every sleeping node holds a residual force below force_wake (1e-5 N by
 * default: a hundred such nodes around the probe add at most 1 mN, 0.1 % of
 * a 1 N press) and no node's state changes while it sleeps.
 * Deterministic: the decisions depend on the state only, in node order;
 * a model built fresh starts with every node awake (so a checkpoint restore
 * and its re-simulation start alike).
 *
 * Ownership: the model (model_mass_spring.c) owns one per mass-spring
 * system and calls build after every change of the springs. Allocation in
 * build only. Not thread-safe: one physics thread. */
#ifndef VISCERA_MS_REGIONS_H
#define VISCERA_MS_REGIONS_H

#include <stddef.h>
#include <stdint.h>

#include "physics/mass_spring.h"
#include "verr.h"

typedef struct ms_regions {
  double force_wake;  /* N: a sleeping node's net force above it wakes it */
  double speed_sleep; /* m/s: an awake node slower than this (and below force_wake / 2) is still */
  uint32_t need;      /* consecutive still sub-steps before a node sleeps */
  /* What build saw (a different spring array or node count needs a build). */
  const ms_spring_t *springs;
  size_t n, nsprings, cap, scap;
  uint32_t *adj_off, *adj; /* node -> its springs (CSR, n + 1 offsets) */
  uint8_t *awake;          /* n */
  uint32_t *still;         /* n: consecutive still sub-steps */
  uint32_t *nbr_awake;     /* n: awake neighbours */
  uint8_t *blk_cnt;        /* per block of 4 springs: awake ends in it (<= 8) */
  uint64_t *blk_bits;      /* blocks with blk_cnt > 0 */
  uint64_t *act_bits;      /* nodes awake or on the frontier */
  uint32_t *list;          /* n: the nodes integrated in the sub-step */
  double *f;               /* 3 n: the sub-step's forces (valid at the marked nodes) */
  size_t nawake;
  /* Counters since create (for tests and benchmarks). */
  uint64_t substeps, node_updates, block_evals, wakes, sleeps, builds;
} ms_regions_t;

/* Thresholds; force_wake > 0 (N), speed_sleep >= 0 (m/s), need >= 1. */
void ms_regions_init(ms_regions_t *r, double force_wake, double speed_sleep, uint32_t need);
void ms_regions_free(ms_regions_t *r);
/* (Re)builds for the springs and nodes of ms as they are now, every free
 * node awake (fixed nodes, inv_mass 0, asleep). 0, or -1 with err (OOM). */
int ms_regions_build(ms_regions_t *r, const mass_spring_t *ms, verr_t *err);
/* 1 when r was built for ms's current springs and nodes. */
int ms_regions_current(const ms_regions_t *r, const mass_spring_t *ms);
/* Node i is touched from outside this sub-step (external force, tool
 * spring): awake now, not still. A fixed or out-of-range node is ignored. */
void ms_regions_touch(ms_regions_t *r, const mass_spring_t *ms, uint32_t i);
/* Every free node awake (still counts restarted). */
void ms_regions_wake_all(ms_regions_t *r, const mass_spring_t *ms);
/* One symplectic Euler sub-step of length h over the awake nodes (the
 * force system's pre_substep already ran; correct_v, when set, is called
 * between kick and drift on the awake nodes' velocities), then the sleep
 * and wake decisions. */
void ms_regions_substep(ms_regions_t *r, mass_spring_t *ms, double h);

#endif
