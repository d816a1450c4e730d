/* SPDX-License-Identifier: Apache-2.0 */
/* rollback_report: how often the server reports rolled-back steps. A seat
 * whose steps keep rolling back (runtime_step) would otherwise write one
 * SessionEvent and one log line per step, 1000 a second: the first rolled
 * step is reported at once, later ones are added up and reported at most
 * once per `every` steps with their count. Judged by the step count, not
 * the clock, so a replay reports the same. Plain data, no allocation; one
 * owner (the server's step thread). */
#ifndef VISCERA_ROLLBACK_REPORT_H
#define VISCERA_ROLLBACK_REPORT_H

#include <stdint.h>

typedef struct rollback_report {
  uint64_t every;      /* steps between two reports (>= 1) */
  uint64_t last_step;  /* step of the last report */
  uint64_t pending;    /* rolled-back organ steps not reported yet */
  uint64_t reports;    /* reports made */
  uint64_t suppressed; /* rolled-back steps that did not report at once */
  int reported;        /* 1 after the first report */
} rollback_report_t;

/* every: steps between reports (0 taken as 1). */
void rollback_report_init(rollback_report_t *r, uint64_t every);
/* After step `step` rolled back `rolled` organs (0: none). Returns 1 when a
 * report is due now, with *count the rolled-back organ steps it covers
 * (this one and those held back since the last report); 0 otherwise. */
int rollback_report_note(rollback_report_t *r, uint64_t step, int rolled, uint64_t *count);
/* Rolled-back steps still held back (reported by the next due report, or by
 * the caller at the end of the run). */
uint64_t rollback_report_pending(const rollback_report_t *r);

#endif
