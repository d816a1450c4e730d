/* SPDX-License-Identifier: Apache-2.0 */
/* haptic_summary: what viscera-haptic prints on exit: rate, period and
 * jitter, force, latency and guiding figures on stderr and one SUMMARY line
 * on stdout (scripts read it). */
#ifndef VISCERA_HAPTIC_SUMMARY_H
#define VISCERA_HAPTIC_SUMMARY_H

#include "guide_report.h"
#include "haptic_dds.h"
#include "haptic_loop.h"

/* Prints the summary. Rewrites st->period_us (into |period - nominal|). */
void haptic_summary_print(const haptic_options_t *o, haptic_stats_t *st, haptic_dds_t *h, const guide_report_t *guide);

#endif
