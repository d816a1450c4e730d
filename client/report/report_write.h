/* report_write: the report files.
 *   report.csv   one row per recording (trainee): identification, every
 *                measure of measure_table.h, thresholds, task times,
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
#include "verr.h"

int rep_write_csv(const rep_recording_t *const *recs, int n, const char *path, verr_t *err);

/* force_png[i]: the force chart of recs[i] (NULL: none); compare_png[m]:
 * the chart of measure m (NULL: none, or fewer than two recordings). */
int rep_write_html(const rep_recording_t *const *recs, int n, const char *const *force_png,
                   const char *const *compare_png, const char *path, verr_t *err);

#endif
