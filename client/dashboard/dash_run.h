/* SPDX-License-Identifier: Apache-2.0 */
/* dash_run: viscera-dashboard once its options are parsed (dashboard.c):
 * open the seats, then draw the grid (and focus view) as PNG frames with a
 * CSV row per seat, or live in a window, until a signal or --duration. */
#ifndef VISCERA_DASH_RUN_H
#define VISCERA_DASH_RUN_H

#define MAX_SEATS 32
#define FOCUS_W 1024 /* default focus view / window size */
#define FOCUS_H 680

typedef struct dash_options {
  const char *prefix, *out, *script; /* --prefix, --out, --script-input (or NULL) */
  int nseats, first;                 /* --seats, --first */
  int tw, th, cols;                  /* --tile WxH, --cols (0: square-ish) */
  int interval_ms;                   /* --interval-ms */
  int focus_seat;                    /* --focus SEAT, 0: none */
  int fw, fh;                        /* --size WxH */
  int window, out_set;               /* --window, --out given */
  double duration, refresh_hz;       /* --duration (0: until a signal), --refresh-hz */
  int domain;                        /* --domain */
} dash_options_t;

/* Exit code: 0 done, 1 on a seat, drawing, window or output error. */
int dash_run(const dash_options_t *o);

#endif
