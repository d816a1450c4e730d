/* SPDX-License-Identifier: Apache-2.0 */
/* guide_report: what a person (and a test) learns about the guiding hand
 * from viscera-haptic's log: one line when the coupling starts, changes
 * (side, authority, stiffness, peer) or stops, stamped with the same loop
 * time t as the force CSV so the two can be lined up, and the time spent
 * coupled on each side for the exit summary. Called once per tick; prints
 * only on a change, so the loop pays a few comparisons. */
#ifndef VISCERA_GUIDE_REPORT_H
#define VISCERA_GUIDE_REPORT_H

#include <stddef.h>
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
  /* Age (us) of the peer position each coupled tick rendered, since it
   * arrived here: how stale the other hand is when felt. Capacity fixed at
   * init (no allocation in the loop); ticks beyond it are not sampled. */
  double *peer_age_us;
  size_t n_age, cap_age;
} guide_report_t;

/* age_capacity: peer-age samples to keep (0: none); -1 when out of memory. */
int guide_report_init(guide_report_t *r, size_t age_capacity);
void guide_report_free(guide_report_t *r);
/* One tick at loop time t: the role, peer and peer age (s) the loop used
 * and what guide_force made of them. Writes a line to log (NULL: none) on a
 * change. */
void guide_report_tick(guide_report_t *r, double t, const guide_role_t *role, const char *peer, double peer_age_s,
                       const guide_output_t *o, FILE *log);
/* Seconds coupled, both sides together, at `period_s` per tick. */
double guide_report_coupled_s(const guide_report_t *r, double period_s);
/* The exit lines, e.g. "GUIDE coupled 3.2 s as owner (trainee), ...,
 * authority 0.50, k 200 N/m, peer bob" and the peer-age statistics, or
 * "GUIDE never coupled". Sorts the age samples. */
void guide_report_summary(const guide_report_t *r, double period_s, FILE *f);

#endif
