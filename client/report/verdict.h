/* SPDX-License-Identifier: Apache-2.0 */
/* verdict: pass or fail of a trainee against limits on the report's
 * measures (measure_table.h), each limit "KEY <= BOUND" or "KEY >= BOUND".
 * BOUND is a number in the measure's unit, or a threshold of the session
 * itself (ST, MPF or SFT, optionally scaled: "1.2*MPF"), so a limit follows
 * the thresholds the instructor set.
 *
 * Defaults (rep_limits_default) judge against the palpation thresholds
 * (docs/methods.md B ch. 6): the peak force stays at or below SFT, no time
 * above SFT, at most 1 s above MPF. A limits file holds one limit per line,
 * '#' starts a comment; a later limit on the same measure and direction
 * replaces the earlier one. */
#ifndef VISCERA_REPORT_VERDICT_H
#define VISCERA_REPORT_VERDICT_H

#include <stdbool.h>

#include "recording_data.h"
#include "verr.h"

#define REP_MAX_LIMITS 24

typedef struct rep_limit {
  int measure;   /* measure_table.h index */
  bool upper;    /* true: value <= bound; false: value >= bound */
  double bound;  /* the number, or the factor of `level` */
  int level;     /* -1: bound is a number; THR_*: bound * that threshold */
  char text[64]; /* as written, for the report */
} rep_limit_t;

typedef struct rep_limits {
  rep_limit_t l[REP_MAX_LIMITS];
  int n;
} rep_limits_t;

typedef enum rep_outcome { REP_PASS, REP_FAIL, REP_NA } rep_outcome_t;

void rep_limits_default(rep_limits_t *ls);
/* Adds (or replaces) the limit in `line`; 0, or -1 with err saying what is
 * wrong (unknown measure, no operator, bad bound). */
int rep_limits_add(rep_limits_t *ls, const char *line, verr_t *err);
/* Replaces ls with the limits of a file; -1 with err naming file and line. */
int rep_limits_load(rep_limits_t *ls, const char *path, verr_t *err);

/* One limit on one recording: the value, the bound in the measure's unit
 * (NAN when the threshold it names is not set) and the outcome (REP_NA
 * when either is unknown). */
rep_outcome_t rep_limit_check(const rep_limit_t *l, const rep_recording_t *r, double *value, double *bound);
/* Every limit: REP_FAIL when any fails, REP_PASS when at least one passed
 * and none failed, else REP_NA. *nfail (may be NULL) counts the failures. */
rep_outcome_t rep_verdict(const rep_limits_t *ls, const rep_recording_t *r, int *nfail);
const char *rep_outcome_name(rep_outcome_t o); /* "PASS", "FAIL", "n/a" */

#endif
