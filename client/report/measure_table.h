/* SPDX-License-Identifier: Apache-2.0 */
/* measure_table: the list of measures a report shows, in one place, so the
 * HTML tables, the CSV columns and the comparison charts cannot disagree on
 * names, units or values. */
#ifndef VISCERA_REPORT_MEASURE_TABLE_H
#define VISCERA_REPORT_MEASURE_TABLE_H

#include "recording_data.h"

typedef struct rep_measure_def {
  const char *key;    /* CSV column, file name part */
  const char *title;  /* human name */
  const char *unit;   /* "N", "s", "cm", "" */
  const char *format; /* printf format of the value */
} rep_measure_def_t;

#define REP_NMEASURES 12

const rep_measure_def_t *rep_measure(int i);
/* The value of measure i for a recording (NAN when not available). */
double rep_measure_value(const rep_recording_t *r, int i);

#endif
