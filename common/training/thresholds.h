/* SPDX-License-Identifier: Apache-2.0 */
/* thresholds: per-tool palpation measures (docs/methods.md B ch. 6). Tracks the
 * contact force magnitude against the tool's three palpation thresholds
 * (ST sound threshold < MPF maximum palpation force <= SFT stopping force
 * threshold) and reports each crossing, upward and downward, with a small
 * hysteresis so a force hovering at a threshold does not chatter. Also
 * accumulates the trainee measures the thesis records: time above each
 * threshold, peak force, exploration (contact) time, mean palpation force
 * while in contact and the length of the path the tool tip travelled.
 *
 * Plain data, no allocation, no networking: the server feeds it once per
 * step; tests drive it directly. */
#ifndef VISCERA_THRESHOLDS_H
#define VISCERA_THRESHOLDS_H

#include <stddef.h>
#include <stdint.h>

typedef enum thr_id { THR_ST, THR_MPF, THR_SFT, THR_COUNT } thr_id_t;

/* Hysteresis band: an upward crossing happens when the force exceeds the
 * level, the matching downward one only when it falls below
 * level - max(THR_HYST_MIN_N, THR_HYST_FRACTION * level). */
#define THR_HYST_FRACTION 0.05
#define THR_HYST_MIN_N 0.01

typedef struct thr_event {
  thr_id_t which;
  int up;       /* 1 = crossed upward, 0 = fell back below (minus hysteresis) */
  double level; /* N */
} thr_event_t;

typedef struct thr_tracker {
  double level[THR_COUNT];       /* N; 0 = not set: never crosses, time above stays 0 */
  int above[THR_COUNT];          /* hysteretic state */
  uint32_t crossings[THR_COUNT]; /* upward crossings */
  double time_above[THR_COUNT];  /* s spent in the "above" state */
  double peak_force;             /* N */
  double contact_time;           /* s in contact (exploration time) */
  double contact_force_integral; /* N s while in contact */
  double path_length;            /* m travelled by the tool tip while driven */
  int have_pos;
  double last_pos[3];
} thr_tracker_t;

const char *thr_name(thr_id_t which);      /* "ST", "MPF", "SFT" */
const char *thr_long_name(thr_id_t which); /* "sound threshold", ... */

/* Levels in N, 0 = not set. */
void thr_init(thr_tracker_t *t, double st, double mpf, double sft);

/* One step of dt seconds: force magnitude (N), whether the tool is in
 * contact, and the tool tip position (NULL when the tool is not driven:
 * the path restarts at the next position instead of jumping to it).
 * Writes at most THR_COUNT events (every threshold crossed this step, in
 * ascending order going up, descending going down) and returns their number. */
int thr_update(thr_tracker_t *t, double dt, double force, int in_contact, const double pos[3],
               thr_event_t ev[THR_COUNT]);

/* Mean palpation force while in contact, N (0 before any contact). */
double thr_mean_contact_force(const thr_tracker_t *t);

#endif
