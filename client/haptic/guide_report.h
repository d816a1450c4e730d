/* guide_report: what a person (and a test) learns about the guiding hand
 * from viscera-haptic's log: one line when the coupling starts, changes
 * (side, authority, stiffness, peer) or stops, stamped with the same loop
 * time t as the force CSV so the two can be lined up, and the time spent
 * coupled on each side for the exit summary. Called once per tick; prints
 * only on a change, so the loop pays a few comparisons. */
#ifndef VISCERA_GUIDE_REPORT_H
#define VISCERA_GUIDE_REPORT_H

#include <stdint.h>
#include <stdio.h>

#include "guide_force.h"

typedef struct guide_report {
  /* Current state, to detect changes. */
  int coupled;
  guide_side_t side;
  double w, k;
  char peer[GUIDE_STATION_MAX];
  uint32_t role_version;
  int role_known;
  const char *why;
  /* Accumulated. */
  uint64_t ticks_owner, ticks_guide; /* coupled ticks per side */
  double last_authority, last_k;     /* of the last coupling */
  char last_peer[GUIDE_STATION_MAX];
  guide_side_t last_side;
  unsigned changes;
} guide_report_t;

void guide_report_init(guide_report_t *r);
/* One tick at loop time t: the role and peer the loop used and what
 * guide_force made of them. Writes a line to log (NULL: none) on a change. */
void guide_report_tick(guide_report_t *r, double t, const guide_role_t *role, const char *peer, const guide_output_t *o,
                       FILE *log);
/* Seconds coupled, both sides together, at `period_s` per tick. */
double guide_report_coupled_s(const guide_report_t *r, double period_s);
/* The exit line, e.g. "GUIDE coupled 3.2 s as owner (trainee), authority
 * 0.50, k 200 N/m, peer bob" or "GUIDE never coupled". */
void guide_report_summary(const guide_report_t *r, double period_s, FILE *f);

#endif
