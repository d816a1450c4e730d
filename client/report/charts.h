/* SPDX-License-Identifier: Apache-2.0 */
/* charts: the report's PNG figures, drawn with common/plot (cairo).
 *   force chart   contact force magnitude over simulated time, one line per
 *                 tool, with the ST / MPF / SFT levels as dashed lines;
 *   comparison    every trainee's force curve on one time axis, and one
 *                 bar chart per measure, one bar per recording.
 * Every function returns 0, or -1 with err naming the file. */
#ifndef VISCERA_REPORT_CHARTS_H
#define VISCERA_REPORT_CHARTS_H

#include "recording_data.h"
#include "verr.h"

int rep_chart_force(const rep_recording_t *r, const char *path, verr_t *err);
/* Every section's contact force (summed over its tools) on one time axis:
 * simulated time since each section's first sample, so sessions that
 * started at different moments line up; the thresholds of the first. */
int rep_chart_force_overlay(const rep_recording_t *const *recs, int n, const char *path, verr_t *err);
/* Measure `measure` (measure_table.h) across `n` recordings. */
int rep_chart_compare(const rep_recording_t *const *recs, int n, int measure, const char *path, verr_t *err);

#endif
