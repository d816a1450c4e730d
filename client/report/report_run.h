/* report_run: viscera-report once its options are parsed (main.c): read
 * each recording, draw the charts, write report.html and report.csv. */
#ifndef VISCERA_REPORT_RUN_H
#define VISCERA_REPORT_RUN_H

#include <stdbool.h>

#define MAX_RECORDINGS 16

typedef struct input {
  const char *path;
  char label[64];
} input_t;

typedef struct report_options {
  const char *out;            /* --out DIR */
  bool quiet;                 /* --quiet */
  input_t in[MAX_RECORDINGS]; /* the recordings, with their labels */
  int nin;
} report_options_t;

/* Exit code: 0 all reported, 1 some recording unusable or output not writable. */
int report_run(const report_options_t *o);

#endif
