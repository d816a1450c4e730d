/* SPDX-License-Identifier: Apache-2.0 */
/* plot_bars: a bar chart (one bar per labelled value, e.g. one per trainee)
 * rendered with cairo into a PNG file, in the palette of plot.h.
 *
 * The value axis starts at zero (bars compare magnitudes, so a cut axis
 * would exaggerate differences); each bar carries its value printed above
 * it. A value that is not finite draws no bar and prints "n/a" instead of
 * pretending to be zero. Labels too long for their slot are shortened with
 * an ellipsis. */
#ifndef VISCERA_PLOT_BARS_H
#define VISCERA_PLOT_BARS_H

#include "verr.h"

#define PLOT_BARS_MAX 16

typedef struct plot_bars {
  char title[160];
  char ylabel[112];
  int n;
  char label[PLOT_BARS_MAX][64];
  double value[PLOT_BARS_MAX];
  int color[PLOT_BARS_MAX]; /* palette index (plot.h) */
  char value_format[16];    /* printf format of one double for the value labels, e.g. "%.2f" */
  int integer_axis;         /* counts: ticks on whole numbers only */
} plot_bars_t;

void plot_bars_init(plot_bars_t *b, const char *title, const char *ylabel, const char *value_format);
/* Returns 0, or -1 when the chart is full. */
int plot_bars_add(plot_bars_t *b, const char *label, double value, int color);
/* Writes a width x height PNG (sizes clamped to 200..2000 px). Returns 0, or
 * -1 with err (no bars, cairo failure). */
int plot_bars_write_png(const plot_bars_t *b, const char *path, int width, int height, verr_t *err);

#endif
