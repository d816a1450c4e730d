/* SPDX-License-Identifier: Apache-2.0 */
/* plot: line charts rendered with cairo into PNG files: the charts of the
 * numerics benchmark (docs/numerics.md §4) and the report tool's time series; bar
 * charts are in plot_bars.h.
 *
 * A plot is a set of series (points joined by lines and/or marked) on linear
 * or logarithmic axes. The legend sits to the right of the plot area, outside
 * it, so it can never hide data. Points that cannot be drawn (NaN, Inf, or
 * <= 0 on a log axis) break the line instead of being dropped silently.
 * Optionally the Pareto front over the series flagged `pareto` is drawn (for
 * work-precision charts: the points no other point beats in both cost and
 * error). */
#ifndef VISCERA_PLOT_H
#define VISCERA_PLOT_H

#include <stddef.h>

#include "verr.h"

#define PLOT_MAX_SERIES 40
#define PLOT_MAX_NOTES 6

enum { PLOT_LINE_NONE = 0, PLOT_LINE_SOLID = 1, PLOT_LINE_DASHED = 2, PLOT_LINE_DOTTED = 3 };
enum { PLOT_BLACK = -1, PLOT_GREY = -2 };

typedef struct plot_series {
  char label[112];
  size_t n;
  double *x, *y; /* owned copies */
  int color;     /* palette index >= 0, or PLOT_BLACK / PLOT_GREY */
  int marker;    /* shape index >= 0, or -1 for none */
  int line;      /* PLOT_LINE_* */
  int pareto;    /* points take part in the Pareto front */
  double *tag;   /* optional number written beside each point (owned), or NULL */
} plot_series_t;

typedef struct plot {
  char title[160], xlabel[112], ylabel[112];
  int logx, logy;
  int nseries;
  plot_series_t s[PLOT_MAX_SERIES];
  int pareto; /* draw the front over the flagged series */
  char empty_suffix[48]; /* appended to the legend of a series with nothing to draw, e.g. " (diverged)" */
  int nnotes;
  char notes[PLOT_MAX_NOTES][480]; /* printed under the legend */
} plot_t;

void plot_init(plot_t *p, const char *title, const char *xlabel, const char *ylabel, int logx, int logy);
/* Copies the points; returns the series (NULL when full or out of memory). */
plot_series_t *plot_add(plot_t *p, const char *label, size_t n, const double *x, const double *y, int color, int marker,
                        int line);
/* Writes tag[i] beside point i (e.g. the sub-step count of a sweep). */
void plot_tag(plot_series_t *s, const double *tag);
void plot_note(plot_t *p, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Writes a 900x600 PNG. Returns 0, or -1 with err (nothing drawable, cairo
 * failure). */
int plot_write_png(const plot_t *p, const char *path, verr_t *err);
void plot_free(plot_t *p);

/* Least-squares slope of log y against log x over the points with y in
 * [ylo, yhi] (finite, positive x); NAN when fewer than 2 qualify. `used`
 * (may be NULL) receives how many points were fitted. */
double plot_loglog_slope(size_t n, const double *x, const double *y, double ylo, double yhi, size_t *used);

/* The RGB (0..1) of a palette index or PLOT_BLACK / PLOT_GREY, so other
 * chart kinds use the same colours. */
void plot_colour_rgb(int color, double rgb[3]);

#endif
