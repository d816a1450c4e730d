/* SPDX-License-Identifier: Apache-2.0 */
/* replay_pause: pausing a replay without losing its original timing.
 *
 * The replay schedules every sample at base_due = pass start + recorded
 * offset / speed (monotonic ns). A pause must not make the samples that
 * fell due while paused go out in a burst at resume: instead the whole rest
 * of the schedule is shifted by the time spent paused, so after resume the
 * samples keep their recorded spacing. Pure (time is an argument), so the
 * arithmetic is unit tested apart from DDS and signals. */
#ifndef VISCERA_REPLAY_PAUSE_H
#define VISCERA_REPLAY_PAUSE_H

#include <stdbool.h>
#include <stdint.h>

typedef struct rpause {
  bool paused;
  int64_t since; /* when the current pause began (valid while paused) */
  int64_t shift; /* total time paused so far: added to every base due time */
} rpause_t;

/* Pauses (no-op when paused already) or resumes (no-op when running) at
 * `now`; resuming adds the paused time to the shift. */
void rpause_set(rpause_t *p, bool paused, int64_t now);
static inline void rpause_toggle(rpause_t *p, int64_t now) { rpause_set(p, !p->paused, now); }

/* When a sample with schedule time `base_due` goes out: base_due + shift,
 * or INT64_MAX while paused (nothing is due). */
int64_t rpause_due(const rpause_t *p, int64_t base_due);

/* Starts a new pass (--loop): the shift is dropped because the pass
 * schedule starts afresh at `now`; a pause in progress continues from now. */
void rpause_new_pass(rpause_t *p, int64_t now);

#endif
