/* SPDX-License-Identifier: Apache-2.0 */
/* haptic_loop: viscera-haptic's fixed-rate loop. Each tick reads the
 * device, writes a ToolCommand, reads the latest contact model and renders
 * the one force law of guide_force.h on the device. */
#ifndef VISCERA_HAPTIC_LOOP_H
#define VISCERA_HAPTIC_LOOP_H

#include <signal.h>
#include <stdint.h>
#include <stdio.h>

#include "device.h"
#include "guide_report.h"
#include "haptic_dds.h"
#include "haptic_options.h"

/* What the loop measured, for the summary (haptic_summary.h). */
typedef struct haptic_stats {
  double *period_us; /* tick periods (us), cap entries */
  size_t nperiod, cap;
  double peak_force, force_sum; /* N; the sum over ticks in contact */
  uint64_t ticks, contact_ticks, late_ticks;
  double elapsed_s;      /* wall time of the loop */
  double script_start_s; /* --start-on-answer: loop time at which the path started (-1: not started) */
  /* Contact under delay (contact_render.h): the passivity observer's
   * largest energy (J, <= 0 passive), the largest one-tick force change
   * (N, cuts excluded), controller ticks, forces cut at a lost server,
   * liveliness losses and stale-feedback episodes. */
  double energy_max_j, energy_j, step_max_n;
  /* The late-model credit C (passivity.h), J, and the largest E - C (J, <= 0 passive). */
  double credit_j, excess_max_j;
  /* Work done over ticks that stalled past the controller's reserve
   * (contact_render.h), J, and the observer's largest value without it. */
  double stall_energy_j, energy_max_unstalled_j;
  uint64_t stall_ticks;
  double guide_rtt_s; /* the round trip the guiding coupling was damped for, s */
  uint64_t pc_ticks, cuts, server_lost, feedback_stale;
  uint64_t liveliness_blips;              /* liveliness lapses heard with feedback still arriving: kept */
  uint64_t reanchored_ticks, plain_ticks; /* in contact: model re-anchored at the answered command, or not */
  uint64_t unplaced_ticks; /* of reanchored_ticks: an answer naming no command we could place (contact_render.h) */
} haptic_stats_t;

typedef struct haptic_loop {
  const haptic_options_t *o;
  device_t *dev;
  haptic_dds_t *h;
  FILE *csv;             /* t,x,y,z,fx,fy,fz,in_contact,energy_j,step_n per tick, or NULL */
  guide_report_t *guide; /* guiding events and ages */
  haptic_stats_t *st;    /* period_us allocated by the caller */
  volatile sig_atomic_t *stop;
} haptic_loop_t;

/* Runs until *stop, --duration, or the end of a scripted trajectory + 0.5 s.
 * Fills st (elapsed_s from the first tick to the return). */
void haptic_loop_run(const haptic_loop_t *l);

#endif
