/* SPDX-License-Identifier: Apache-2.0 */
/* seat_group: several seats' sessions (server.h) stepped by one thread.
 *
 * Why: with a physics thread per seat, five busy seats on two cores each
 * wake into a core that other seats' threads, their DDS sends and their
 * clients have just used, and every step pays for it (docs/numerics.md
 * §11.3). One thread per core stepping its seats one after the other runs
 * each seat's tissue step right after another seat's (the same code on the
 * same core, bench_seats' arrangement), and sleeps once per tick instead
 * of once per seat.
 *
 * Each tick, in this order: every seat's server_step_begin (commands,
 * contact phase, early ContactFeedback: a seat's answer never waits for
 * another seat's tissue), every seat's server_step_tissue, every seat's
 * server_step_end (frames, events, metrics, checkpoints), then one sleep to
 * the next tick. A seat whose step_begin fails (its scene could not be
 * rebuilt) stops; the others go on. Falling more than SERVER_RESYNC_NS
 * behind counts an overrun in every seat of the group and starts again
 * from now.
 *
 * Trade-off: a seat's long step (a cut's re-meshing) delays the other
 * seats of its group for as long; with a thread per seat the scheduler
 * shares the cores among them instead. */
#ifndef VISCERA_SESSION_SEAT_GROUP_H
#define VISCERA_SESSION_SEAT_GROUP_H

#include <signal.h>

#include "session/server.h"

typedef struct seat_group_member {
  const scene_t *scene;      /* in: outlives the run */
  const server_opts_t *opts; /* in: its own partition, tag, files; duration and rt_priority of the first member rule
                                the group */
  const char *name;          /* in: for the error line ("seat 'NAME': ...") */
  server_stats_t *stats;     /* out: server_close's figures */
  int rc;                    /* out: 0, or 1 when the session could not start (err says why, also printed) */
  verr_t err;
} seat_group_member_t;

/* Runs the group on the calling thread (it becomes their physics loop:
 * server_thread_prepare) until *stop is set or the first member's
 * duration has passed; opens the members in order and closes them all
 * before it returns. */
void seat_group_run(seat_group_member_t *m, int n, volatile sig_atomic_t *stop);

/* One session, the same loop (a group of one): set-up, steps until *stop or
 * opts->duration, shutdown. Returns 0, or -1 with err (not printed) when
 * the session could not start. */
int server_run(const scene_t *scene, const server_opts_t *opts, volatile sig_atomic_t *stop, server_stats_t *stats,
               verr_t *err);

#endif
