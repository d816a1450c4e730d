/* SPDX-License-Identifier: Apache-2.0 */
/* organ_sleep: an organ at rest is not stepped until something can touch it.
 *
 * Why: a classroom runs one server per seat on shared machines, and a
 * trainee's organ spends most of a session untouched and still. Stepping
 * it then costs a full physics step (a 2,000-vertex kidney: ~0.3 ms of
 * every 1 ms) to compute a state that does not change, and its viewers
 * receive the same mesh again. Rigid-body engines put resting bodies to
 * sleep for the same reason; here the test is on the organ's surface, so
 * it holds for every deformation model.
 *
 * The rule (scene keys physics.sleep_speed, physics.sleep_after):
 * - An organ falls asleep after `need` consecutive steps in which no
 *   surface vertex moved more than `max_move` (sleep_speed * dt) and
 *   nothing could touch it (`disturbed` 0: see runtime's test, no tool
 *   within reach of its bounding box, no grasp, no held stone, no cut).
 * - Asleep, it is skipped: its state (positions AND velocities) is kept
 *   exactly, so waking is a pause ending, never a jump; the only physics
 *   lost is the residual motion below sleep_speed during the sleep.
 * - It wakes, before the step, as soon as anything could touch it.
 * Only the caller (the runtime) decides what "could touch" means; this
 * file keeps the evidence of stillness and the counters. Not thread-safe. */
#ifndef VISCERA_ORGAN_SLEEP_H
#define VISCERA_ORGAN_SLEEP_H

#include <stddef.h>
#include <stdint.h>

#include "verr.h"

typedef struct organ_sleep {
  double *prev;   /* 3 n: the surface after the previous observed step */
  size_t n, cap;  /* vertices in prev, capacity */
  uint32_t still; /* consecutive still, undisturbed steps */
  int have_prev;  /* prev holds a surface of n vertices */
  int asleep;
  uint64_t slept_steps; /* steps skipped while asleep */
  uint64_t sleeps;      /* times it fell asleep */
  uint64_t wakes;       /* times it woke */
} organ_sleep_t;

/* Allocates room for nsurf vertices. Returns 0, or -1 with err (OOM). */
int organ_sleep_init(organ_sleep_t *s, size_t nsurf, verr_t *err);
void organ_sleep_free(organ_sleep_t *s);

/* After a step of the organ with surface x (n vertices): records the
 * surface and updates the stillness count. A step counts as still when
 * every vertex moved at most max_move (NaN counts as moving) and
 * `disturbed` is 0. A different n (the topology changed) restarts the
 * evidence; it reallocates then, the only allocation. Returns 1 when the
 * organ falls asleep with this step (need still steps reached), else 0;
 * -1 on OOM (the organ then stays awake). */
int organ_sleep_observe(organ_sleep_t *s, const double *x, size_t n, double max_move, uint32_t need, int disturbed);
/* The same, the same result, for a caller that knows only the nidx
 * vertices in idx can differ from the surface of the previous observation
 * (a model's last_step_moved): O(nidx) instead of O(n). idx NULL: every
 * vertex (organ_sleep_observe). */
int organ_sleep_observe_listed(organ_sleep_t *s, const double *x, size_t n, const uint32_t *idx, size_t nidx,
                               double max_move, uint32_t need, int disturbed);

/* Wakes the organ (if asleep) and restarts the evidence of stillness. */
void organ_sleep_wake(organ_sleep_t *s);

/* 1 when the segment p0-p1 swollen by `reach` (a capsule's bounding box)
 * overlaps the box lo..hi. A bounding-box test: it may say near when the
 * capsule is not (the organ then just stays awake), never the reverse. */
int organ_sleep_box_near(const double lo[3], const double hi[3], const double p0[3], const double p1[3], double reach);

#endif
