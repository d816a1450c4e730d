/* SPDX-License-Identifier: Apache-2.0 */
/* plot_bars: cairo bar charts. See plot_bars.h. */
#include "plot/plot_bars.h"

#include <cairo.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "plot/plot.h"

#define FONT "DejaVu Sans"

void plot_bars_init(plot_bars_t *b, const char *title, const char *ylabel, const char *value_format) {
  memset(b, 0, sizeof *b);
  snprintf(b->title, sizeof b->title, "%s", title);
  snprintf(b->ylabel, sizeof b->ylabel, "%s", ylabel);
  snprintf(b->value_format, sizeof b->value_format, "%s", value_format ? value_format : "%.3g");
}

int plot_bars_add(plot_bars_t *b, const char *label, double value, int color) {
  if (b->n >= PLOT_BARS_MAX) return -1;
  snprintf(b->label[b->n], sizeof b->label[0], "%s", label);
  b->value[b->n] = value;
  b->color[b->n] = color;
  b->n++;
  return 0;
}

/* A "nice" step (1, 2 or 5 x 10^k) giving about `want` intervals up to hi. */
static double nice_step(double hi, int want) {
  double raw = hi / want, mag = pow(10, floor(log10(raw))), r = raw / mag;
  return (r > 5 ? 10 : r > 2 ? 5 : r > 1 ? 2 : 1) * mag;
}

/* Draws `text` centred on x, shortened with "..." to fit `width` px. */
static void centred_text(cairo_t *cr, const char *text, double x, double y, double width) {
  char buf[80];
  snprintf(buf, sizeof buf, "%s", text);
  cairo_text_extents_t e;
  cairo_text_extents(cr, buf, &e);
  size_t len = strlen(buf);
  while (e.x_advance > width && len > 4) {
    len--;
    memcpy(buf + len - 3, "...", 4);
    buf[len] = 0;
    cairo_text_extents(cr, buf, &e);
  }
  cairo_move_to(cr, x - e.x_advance / 2, y);
  cairo_show_text(cr, buf);
}

int plot_bars_write_png(const plot_bars_t *b, const char *path, int width, int height, verr_t *err) {
  if (b->n <= 0) return verr_set(err, "%s: bar chart '%s' has no bars", path, b->title);
  int W = width < 200 ? 200 : width > 2000 ? 2000 : width;
  int H = height < 200 ? 200 : height > 2000 ? 2000 : height;
  double vmax = 0;
  for (int i = 0; i < b->n; i++)
    if (isfinite(b->value[i]) && b->value[i] > vmax) vmax = b->value[i];
  if (!(vmax > 0)) vmax = 1;
  double step = nice_step(vmax * 1.12, 5);
  if (b->integer_axis && step < 1) step = 1;
  double top = ceil(vmax * 1.12 / step) * step; /* room for the value labels */

  cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
  cairo_t *cr = cairo_create(surf);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_select_font_face(cr, FONT, CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);

  /* Left margin from the widest tick label. */
  char tick[32];
  cairo_set_font_size(cr, 11);
  double tw = 0;
  for (double v = 0; v <= top + 1e-9 * top; v += step) {
    snprintf(tick, sizeof tick, "%g", v);
    cairo_text_extents_t e;
    cairo_text_extents(cr, tick, &e);
    tw = fmax(tw, e.x_advance);
  }
  double x0 = 34 + tw, x1 = W - 12, y0 = H - 40, y1 = 40;

  /* Title. */
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_select_font_face(cr, FONT, CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_font_size(cr, 13);
  centred_text(cr, b->title, W / 2.0, 22, W - 16);
  cairo_select_font_face(cr, FONT, CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);

  /* Grid and value axis. */
  cairo_set_font_size(cr, 11);
  for (double v = 0; v <= top + 1e-9 * top; v += step) {
    double y = y0 - v / top * (y0 - y1);
    cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
    cairo_set_line_width(cr, 1);
    cairo_move_to(cr, x0, floor(y) + 0.5);
    cairo_line_to(cr, x1, floor(y) + 0.5);
    cairo_stroke(cr);
    snprintf(tick, sizeof tick, "%g", v);
    cairo_text_extents_t e;
    cairo_text_extents(cr, tick, &e);
    cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
    cairo_move_to(cr, x0 - 6 - e.x_advance, y + 4);
    cairo_show_text(cr, tick);
  }
  cairo_save(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_move_to(cr, 15, (y0 + y1) / 2);
  cairo_rotate(cr, -1.5707963267948966); /* -pi/2: text reads upward */
  {
    cairo_text_extents_t e;
    cairo_text_extents(cr, b->ylabel, &e);
    cairo_rel_move_to(cr, -e.x_advance / 2, 0);
    cairo_show_text(cr, b->ylabel);
  }
  cairo_restore(cr);

  /* Bars: slots of equal width, the bar 60 % of its slot (at most 90 px). */
  double slot = (x1 - x0) / b->n, bw = fmin(0.6 * slot, 90);
  for (int i = 0; i < b->n; i++) {
    double cx = x0 + (i + 0.5) * slot, v = b->value[i];
    char val[48];
    double ytext;
    if (isfinite(v)) {
      double h = fmax(v, 0) / top * (y0 - y1);
      double rgb[3];
      plot_colour_rgb(b->color[i], rgb);
      cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
      cairo_rectangle(cr, cx - bw / 2, y0 - h, bw, h);
      cairo_fill(cr);
      snprintf(val, sizeof val, b->value_format, v);
      ytext = y0 - h - 5;
    } else {
      snprintf(val, sizeof val, "n/a");
      ytext = y0 - 5;
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_font_size(cr, 11);
    centred_text(cr, val, cx, ytext, slot);
    cairo_set_font_size(cr, 11.5);
    centred_text(cr, b->label[i], cx, y0 + 17, slot - 4);
  }
  /* Base line over the bars' feet. */
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 1.2);
  cairo_move_to(cr, x0, floor(y0) + 0.5);
  cairo_line_to(cr, x1, floor(y0) + 0.5);
  cairo_move_to(cr, floor(x0) + 0.5, y0);
  cairo_line_to(cr, floor(x0) + 0.5, y1);
  cairo_stroke(cr);

  cairo_status_t cs = cairo_surface_write_to_png(surf, path);
  cairo_destroy(cr);
  cairo_surface_destroy(surf);
  if (cs != CAIRO_STATUS_SUCCESS) return verr_set(err, "%s: cannot write PNG: %s", path, cairo_status_to_string(cs));
  return 0;
}
