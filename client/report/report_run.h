/* SPDX-License-Identifier: Apache-2.0 */
/* report_run: viscera-report once its options are parsed (main.c): read
 * each recording, draw the charts, write report.html and report.csv. */
#ifndef VISCERA_REPORT_RUN_H
#define VISCERA_REPORT_RUN_H

#include <stdbool.h>

#include "verdict.h"

#define MAX_RECORDINGS 16
/* Sections of a report: one per recording, or per seat of a lab recording. */
#define MAX_SECTIONS 64

typedef struct input {
  const char *path;
  char label[64];
} input_t;

typedef struct report_options {
  const char *out;            /* --out DIR */
  bool quiet;                 /* --quiet */
  input_t in[MAX_RECORDINGS]; /* the recordings, with their labels */
  int nin;
  rep_limits_t limits; /* the verdict's limits: defaults, --limits FILE, --limit */
} report_options_t;

/* A recording made with a partition pattern (deploy/lab.sh records every lab/ partition)
 * holds several seats: it is reported seat by seat, each section counting
 * only that seat's samples, with a lab summary table first.
 * Exit code: 0 all reported, 1 some recording unusable or output not writable. */
int report_run(const report_options_t *o);

#endif
