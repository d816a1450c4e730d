/* SPDX-License-Identifier: Apache-2.0 */
/* options: the viscera-viewer command line (getopt_long). */
#ifndef VISCERA_VIEWER_OPTIONS_H
#define VISCERA_VIEWER_OPTIONS_H

#include <stdio.h>

#include "verr.h"

typedef struct viewer_opts {
  int domain;               /* DDS domain id */
  const char *partition;    /* session partition */
  const char *out_dir;      /* frames and frames.csv go here */
  int interval_ms;          /* wall-time frame period; 0 = only on SIGUSR1 */
  int width, height;        /* frame size in pixels */
  int tools;                /* draw tools, proxy and force bar */
  double duration_s;        /* stop after this long; 0 = until SIGINT/SIGTERM */
  long max_frames;          /* stop after this many frames; 0 = no limit */
  const char *dump_mesh;    /* OBJ path written on exit, or NULL */
  int quiet;                /* no progress lines on stdout */
  int out_set;              /* --out was given (the window writes frames only then) */
  int window;               /* --window: interactive SDL2 window (window.h) */
  int drive_tool;           /* --drive N: tool driven by mouse and keyboard; -1 = none */
  const char *script_input; /* --script-input FILE: timed input events (input_script.h) */
} viewer_opts_t;

/* Defaults, then the environment (VISCERA_DOMAIN), then argv, through the
 * shared parser (common/cli.h: --domain, --partition, --quiet, --help,
 * --version). Returns CLI_RUN to run, else the exit code: 0 after --help or
 * --version (printed), 2 after a usage error (printed on stderr).
 * Strings point into argv or static storage. */
int options_parse(viewer_opts_t *o, int argc, char **argv);
void options_usage(FILE *f, const char *prog);

#endif
