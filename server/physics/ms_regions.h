/* SPDX-License-Identifier: Apache-2.0 */
/* ms_regions: regional sleeping for the explicit mass-spring step (issue 17):
 * only the nodes that move, and their springs, are integrated.
 *
 * Why: in an explicit scheme a disturbance travels at most one spring per
 * sub-step, and under a local press most of a large organ is at rest (the
 * home springs, as stiff as the edges, make the static response decay
 * within a few rings of the probe). Evaluating and integrating the still
 * part cost most of the step on a 23.5k-vertex liver for nothing.
 *
 * The rule, per node, one sub-step of symplectic Euler at a time:
 * - An awake node falls asleep at the end of a sub-step in which its speed
 *   (after the kick) stayed below speed_sleep, its net force below
 *   force_wake / 2, and no external force or tool spring touched it. Its
 *   velocity is then set to 0; asleep, its position is kept bit for bit:
 *   it is not integrated, and the springs between two sleeping nodes are
 *   not evaluated.
 * - A sleeping node next to an awake one (the frontier), and every node
 *   for one sub-step after it or a neighbour fell asleep, has its net force
 *   evaluated; above force_wake it wakes and is integrated from that
 *   sub-step on. Every other sleeping node feels the force it had when it
 *   was last evaluated (nothing around it moved since), at most force_wake.
 * - An external force or a tool spring on a node wakes it at once, before
 *   the forces of the sub-step.
 * So every sleeping node holds a residual force of at most force_wake (1e-5
 * N by default: a hundred such nodes around the probe add at most 1 mN,
 * 0.1 % of a 1 N press).
 *
 * No memory beyond the state: at every step boundary the sleeping nodes
 * are exactly the free nodes with zero velocity and a net force of at most
 * force_wake (an awake node never ends a sub-step exactly at rest with so
 * small a force: it would have fallen asleep), and the force rows the
 * sleeping springs keep are those of the current positions. ms_regions_build
 * derives the sets from the state that way, so a model built fresh (a
 * checkpoint restore, a re-simulation) continues bit for bit as the running
 * one would (test_checkpoint, resim_*). The model rebuilds after a topology
 * change, a rollback, a change of material, and whenever a sleeping node's
 * position or velocity changed from outside between steps (seen after a
 * write noted through model_note_outside_write: ms_regions_begin_step).
 *
 * Ownership: the model (model_mass_spring.c) owns one per mass-spring
 * system. Allocation in build only. Not thread-safe: one physics thread. */
#ifndef VISCERA_MS_REGIONS_H
#define VISCERA_MS_REGIONS_H

#include <stddef.h>
#include <stdint.h>

#include "physics/mass_spring.h"
#include "verr.h"

typedef struct ms_regions {
  double force_wake;  /* N: a sleeping node's net force above it wakes it */
  double speed_sleep; /* m/s: an awake node slower than this (and below force_wake / 2) falls asleep */
  /* What build saw (another spring array or node count needs a build). */
  const ms_spring_t *springs;
  size_t n, nsprings, cap, scap;
  uint32_t *adj_off, *adj; /* node -> its springs (CSR, n + 1 offsets) */
  uint8_t *awake;          /* n: integrated */
  uint8_t *held;           /* n: counted below (awake, or fell asleep in the last sub-step) */
  uint8_t *touched;        /* n: external force or tool spring in this sub-step */
  uint32_t *nbr_held;      /* n: held neighbours */
  uint8_t *blk_cnt;        /* per block of 4 springs: held ends in it (<= 8) */
  uint64_t *blk_bits;      /* blocks with blk_cnt > 0: evaluated */
  uint64_t *act_bits;      /* nodes held or next to a held one: force evaluated */
  uint32_t *list;          /* n: the nodes integrated in the sub-step */
  uint32_t *pend, *pend2;  /* n each: nodes that fell asleep in the last sub-step (still held) */
  size_t npend;
  double *f;  /* 3 n: the sub-step's forces (valid at the act nodes) */
  double *xs; /* 3 n: where each sleeping node sleeps (to see a write from outside) */
  /* The step's guard (begin_step .. end_step): the nodes the step may
   * change, with their state from before it (awake ones at the start,
   * woken ones when they wake: asleep, they had not moved). */
  double *gx, *gv;
  uint32_t *gidx;
  uint8_t *saved;
  size_t gn;
  int in_step;
  double *sx, *sv; /* the state being stepped (ms->x, ms->v) */
  size_t nawake;
  /* Counters since init (for tests and benchmarks). */
  uint64_t substeps, node_updates, block_evals, wakes, sleeps, builds;
  uint64_t sleeper_checks; /* passes over every node after a write from outside */
} ms_regions_t;

/* Thresholds: force_wake > 0 (N), speed_sleep >= 0 (m/s). */
void ms_regions_init(ms_regions_t *r, double force_wake, double speed_sleep);
void ms_regions_free(ms_regions_t *r);
/* (Re)builds for the springs and nodes of ms as they are now and derives
 * who sleeps from the state (above); evaluates every spring once.
 * 0, or -1 with err (OOM: r is then not current). */
int ms_regions_build(ms_regions_t *r, const mass_spring_t *ms, verr_t *err);
/* 1 when r was built for ms's current springs and nodes. */
int ms_regions_current(const ms_regions_t *r, const mass_spring_t *ms);
/* The start of a step: checks that the awake nodes are finite and keeps
 * their state for a rollback; when `written` (the state was written from
 * outside since the last step: model.h outside_writes), first checks in
 * one pass over every node that each node it holds asleep is still where
 * it fell asleep, at zero velocity. 0, or -1 (something changed from
 * outside, or not finite; nothing kept: the caller builds again and
 * guards the step itself). Without a write from outside the step's guard
 * costs what the awake nodes cost, not the organ. Builds with
 * VISCERA_CHECK_OUTSIDE_WRITES (the sanitizer configuration) always look
 * and abort when a sleeping node changed without `written`. */
int ms_regions_begin_step(ms_regions_t *r, mass_spring_t *ms, int written);
/* The end of that step: 0 when every node the step may have changed is
 * finite; otherwise puts them back as before the step, counts the rollback
 * in *rollbacks, leaves r to be built again, and returns -1. */
int ms_regions_end_step(ms_regions_t *r, mass_spring_t *ms, uint64_t *rollbacks);
/* Node i is touched from outside in this sub-step (external force, tool
 * spring): awake now. A fixed or out-of-range node is ignored. */
void ms_regions_touch(ms_regions_t *r, const mass_spring_t *ms, uint32_t i);
/* One symplectic Euler sub-step of length h over the awake nodes (the
 * force system's pre_substep already ran; correct_v, when set, is called
 * between kick and drift), then the sleep and wake decisions. */
void ms_regions_substep(ms_regions_t *r, mass_spring_t *ms, double h);

#endif
