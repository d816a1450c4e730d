/* SPDX-License-Identifier: Apache-2.0 */
/* report_write: the report files.
 *   report.csv   one row per recording or seat (trainee): identification
 *                (seat, station), every measure of measure_table.h,
 *                thresholds, task times by task, verdict and failed limits,
 *                warnings count; numbers in C locale, empty when unknown.
 *   report.html  one self-contained page: per recording its metadata,
 *                warnings, measures and force chart; with several
 *                recordings a comparison table and one bar chart per
 *                measure. PNGs are embedded as base64 data URIs, so the
 *                page needs no other file.
 * Both return 0, or -1 with err naming the file. */
#ifndef VISCERA_REPORT_WRITE_H
#define VISCERA_REPORT_WRITE_H

#include "recording_data.h"
#include "verdict.h"
#include "verr.h"

/* The charts drawn for the page (NULL entries: none). */
typedef struct rep_charts {
  const char *const *force_png;   /* [i]: the force chart of recs[i] */
  const char *const *compare_png; /* [m]: measure m across recordings (two or more) */
  const char *overlay_png;        /* every force curve on one time axis */
} rep_charts_t;

typedef struct rep_layout {
  const rep_limits_t *limits; /* the verdict's */
  bool lab;                   /* sections are the seats of a lab recording */
} rep_layout_t;

int rep_write_csv(const rep_recording_t *const *recs, int n, const rep_limits_t *limits, const char *path, verr_t *err);

/* A summary table first (with two or more sections: "Lab summary" for a
 * lab), then per section its identity, verdict, measures and force chart,
 * then the comparison. Print CSS: each section starts a page, tables and
 * charts are not split, the page fits A4. */
int rep_write_html(const rep_recording_t *const *recs, int n, const rep_charts_t *charts, const rep_layout_t *layout,
                   const char *path, verr_t *err);

#endif
