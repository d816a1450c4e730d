/* SPDX-License-Identifier: Apache-2.0 */
/* plot: cairo rendering of line charts. See plot.h. */
#include "plot/plot.h"

#include <cairo.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define W 900
#define H 600
#define FONT "DejaVu Sans"

/* Ten colours that stay distinct on white and for the common colour
 * deficiencies (the "tab10" set without its grey, which reference lines use),
 * then six darker ones for crowded charts. */
static const double PALETTE[][3] = {
    {0.122, 0.467, 0.706}, {1.000, 0.498, 0.055}, {0.173, 0.627, 0.173}, {0.839, 0.153, 0.157},
    {0.580, 0.404, 0.741}, {0.549, 0.337, 0.294}, {0.890, 0.467, 0.761}, {0.737, 0.741, 0.133},
    {0.090, 0.745, 0.812}, {0.224, 0.231, 0.475}, {0.906, 0.729, 0.322}, {0.388, 0.475, 0.224},
    {0.518, 0.235, 0.224}, {0.000, 0.000, 0.502}, {0.400, 0.400, 0.000}, {0.000, 0.400, 0.400},
};
#define NPALETTE ((int)(sizeof PALETTE / sizeof PALETTE[0]))

void plot_init(plot_t *p, const char *title, const char *xlabel, const char *ylabel, int logx, int logy) {
  memset(p, 0, sizeof *p);
  snprintf(p->title, sizeof p->title, "%s", title);
  snprintf(p->xlabel, sizeof p->xlabel, "%s", xlabel);
  snprintf(p->ylabel, sizeof p->ylabel, "%s", ylabel);
  p->logx = logx;
  p->logy = logy;
}

plot_series_t *plot_add(plot_t *p, const char *label, size_t n, const double *x, const double *y, int color, int marker,
                        int line) {
  if (p->nseries >= PLOT_MAX_SERIES) return NULL;
  plot_series_t *s = &p->s[p->nseries];
  memset(s, 0, sizeof *s);
  s->x = malloc((n ? n : 1) * sizeof *s->x);
  s->y = malloc((n ? n : 1) * sizeof *s->y);
  if (!s->x || !s->y) {
    free(s->x);
    free(s->y);
    return NULL;
  }
  if (n) {
    memcpy(s->x, x, n * sizeof *x);
    memcpy(s->y, y, n * sizeof *y);
  }
  s->n = n;
  snprintf(s->label, sizeof s->label, "%s", label);
  s->color = color;
  s->marker = marker;
  s->line = line;
  p->nseries++;
  return s;
}

void plot_tag(plot_series_t *s, const double *tag) {
  if (!s) return;
  free(s->tag);
  s->tag = malloc((s->n ? s->n : 1) * sizeof *s->tag);
  if (s->tag && s->n) memcpy(s->tag, tag, s->n * sizeof *tag);
}

void plot_note(plot_t *p, const char *fmt, ...) {
  if (p->nnotes >= PLOT_MAX_NOTES) return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(p->notes[p->nnotes++], sizeof p->notes[0], fmt, ap);
  va_end(ap);
}

void plot_free(plot_t *p) {
  for (int i = 0; i < p->nseries; i++) {
    free(p->s[i].x);
    free(p->s[i].y);
    free(p->s[i].tag);
  }
  p->nseries = 0;
}

double plot_loglog_slope(size_t n, const double *x, const double *y, double ylo, double yhi, size_t *used) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  size_t k = 0;
  for (size_t i = 0; i < n; i++) {
    if (!(x[i] > 0) || !isfinite(x[i]) || !(y[i] >= ylo && y[i] <= yhi) || !(y[i] > 0)) continue;
    double lx = log(x[i]), ly = log(y[i]);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
    k++;
  }
  if (used) *used = k;
  double den = (double)k * sxx - sx * sx;
  if (k < 2 || !(fabs(den) > 1e-300)) return NAN;
  return ((double)k * sxy - sx * sy) / den;
}

/* ---- axes ---------------------------------------------------------------- */

typedef struct axis {
  int log;
  double lo, hi;     /* in axis units: log10(value) on log axes */
  double p0, p1;     /* pixel positions of lo and hi */
} axis_t;

static int drawable(const axis_t *a, double v) { return isfinite(v) && (!a->log || v > 0); }
static double to_unit(const axis_t *a, double v) { return a->log ? log10(v) : v; }
static double to_px(const axis_t *a, double v) {
  return a->p0 + (to_unit(a, v) - a->lo) / (a->hi - a->lo) * (a->p1 - a->p0);
}

/* Range from the data with a 5 % margin, so no marker sits on the frame; a
 * log axis spanning two or more decades then widens to the next decade
 * line when that is close (ticks at both ends). */
static void axis_fit(axis_t *a, double vmin, double vmax) {
  double lo = to_unit(a, vmin), hi = to_unit(a, vmax);
  if (!(hi - lo > 1e-12 * (fabs(lo) + fabs(hi) + 1e-300))) {
    double d = a->log ? 0.5 : (fabs(lo) > 0 ? 0.1 * fabs(lo) : 1);
    lo -= d;
    hi += d;
  }
  double span = hi - lo;
  lo -= 0.05 * span;
  hi += 0.05 * span;
  if (a->log && span >= 2) {
    double near = fmin(0.12 * span, 0.35);
    if (lo - floor(lo) < near) lo = floor(lo);
    if (ceil(hi) - hi < near) hi = ceil(hi);
  }
  a->lo = lo;
  a->hi = hi;
}

void plot_colour_rgb(int c, double rgb[3]) {
  if (c == PLOT_BLACK) {
    rgb[0] = rgb[1] = rgb[2] = 0;
  } else if (c == PLOT_GREY) {
    rgb[0] = rgb[1] = rgb[2] = 0.45;
  } else {
    const double *k = PALETTE[(c % NPALETTE + NPALETTE) % NPALETTE];
    rgb[0] = k[0], rgb[1] = k[1], rgb[2] = k[2];
  }
}

static void set_colour(cairo_t *cr, int c) {
  double k[3];
  plot_colour_rgb(c, k);
  cairo_set_source_rgb(cr, k[0], k[1], k[2]);
}

static void set_line(cairo_t *cr, int style, double width) {
  cairo_set_line_width(cr, width);
  if (style == PLOT_LINE_DASHED) {
    double d[2] = {7, 4};
    cairo_set_dash(cr, d, 2, 0);
  } else if (style == PLOT_LINE_DOTTED) {
    double d[2] = {1.5, 3.5};
    cairo_set_dash(cr, d, 2, 0);
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  } else {
    cairo_set_dash(cr, NULL, 0, 0);
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
  }
}

/* A grid line at a tick: major ticks a darker grey than minor ones. */
static void grid_line(cairo_t *cr, int major, double x0, double y0, double x1, double y1) {
  double g = major ? 0.85 : 0.93;
  cairo_set_source_rgb(cr, g, g, g);
  set_line(cr, PLOT_LINE_SOLID, 1);
  cairo_move_to(cr, x0, y0);
  cairo_line_to(cr, x1, y1);
  cairo_stroke(cr);
}

static void marker(cairo_t *cr, int shape, double x, double y, double r) {
  cairo_set_dash(cr, NULL, 0, 0);
  cairo_new_path(cr);
  switch (shape % 7) {
  case 0: cairo_arc(cr, x, y, r, 0, 2 * M_PI); break;
  case 1: cairo_rectangle(cr, x - 0.85 * r, y - 0.85 * r, 1.7 * r, 1.7 * r); break;
  case 2:
    cairo_move_to(cr, x, y - 1.15 * r);
    cairo_line_to(cr, x + r, y + 0.75 * r);
    cairo_line_to(cr, x - r, y + 0.75 * r);
    cairo_close_path(cr);
    break;
  case 3:
    cairo_move_to(cr, x, y - 1.2 * r);
    cairo_line_to(cr, x + r, y);
    cairo_line_to(cr, x, y + 1.2 * r);
    cairo_line_to(cr, x - r, y);
    cairo_close_path(cr);
    break;
  case 4:
    cairo_move_to(cr, x, y + 1.15 * r);
    cairo_line_to(cr, x + r, y - 0.75 * r);
    cairo_line_to(cr, x - r, y - 0.75 * r);
    cairo_close_path(cr);
    break;
  case 5: /* x: stroked, it has no inside */
    cairo_set_line_width(cr, 2);
    cairo_move_to(cr, x - r, y - r);
    cairo_line_to(cr, x + r, y + r);
    cairo_move_to(cr, x - r, y + r);
    cairo_line_to(cr, x + r, y - r);
    cairo_stroke(cr);
    return;
  default: /* + */
    cairo_set_line_width(cr, 2);
    cairo_move_to(cr, x - 1.2 * r, y);
    cairo_line_to(cr, x + 1.2 * r, y);
    cairo_move_to(cr, x, y - 1.2 * r);
    cairo_line_to(cr, x, y + 1.2 * r);
    cairo_stroke(cr);
    return;
  }
  cairo_fill(cr);
}

/* Tick text: plain decimals where they stay short, else mantissa x 10^e with
 * the exponent drawn as a superscript. */
typedef struct ticklabel {
  char base[32], exp[16];
} ticklabel_t;

static ticklabel_t format_tick(double v, int log_axis) {
  ticklabel_t t;
  memset(&t, 0, sizeof t);
  double a = fabs(v);
  if (v == 0 || (a >= 1e-3 && a < 1e5)) {
    snprintf(t.base, sizeof t.base, "%.6g", v);
    return t;
  }
  int e = (int)floor(log10(a) + 1e-9);
  double m = v / pow(10, e);
  if (log_axis && fabs(m - 1) < 1e-6) snprintf(t.base, sizeof t.base, "10");
  else snprintf(t.base, sizeof t.base, "%.3gx10", m);
  snprintf(t.exp, sizeof t.exp, "%d", e);
  return t;
}

/* Width of a tick label at the current font size. */
static double tick_width(cairo_t *cr, const ticklabel_t *t, double size) {
  cairo_text_extents_t e;
  cairo_set_font_size(cr, size);
  cairo_text_extents(cr, t->base, &e);
  double w = e.x_advance;
  if (t->exp[0]) {
    cairo_set_font_size(cr, size * 0.72);
    cairo_text_extents(cr, t->exp, &e);
    w += e.x_advance;
    cairo_set_font_size(cr, size);
  }
  return w;
}

/* Draws the label with its left edge at x and baseline at y. */
static void tick_draw(cairo_t *cr, const ticklabel_t *t, double x, double y, double size) {
  cairo_text_extents_t e;
  cairo_set_font_size(cr, size);
  cairo_move_to(cr, x, y);
  cairo_show_text(cr, t->base);
  cairo_text_extents(cr, t->base, &e);
  if (t->exp[0]) {
    cairo_set_font_size(cr, size * 0.72);
    cairo_move_to(cr, x + e.x_advance, y - size * 0.45);
    cairo_show_text(cr, t->exp);
    cairo_set_font_size(cr, size);
  }
}

typedef struct tick {
  double v; /* value (not log) */
  int major, labelled;
} tick_t;

/* Tick positions: decades (and 2..9 minors) on log axes, 1-2-5 steps on
 * linear ones. On a log axis spanning under two decades the 2 and 5 minors
 * get labels too, so the reader always has at least three numbers. */
static int make_ticks(const axis_t *a, tick_t *t, int cap) {
  int n = 0;
  if (a->log) {
    int d0 = (int)floor(a->lo), d1 = (int)ceil(a->hi);
    int span = d1 - d0, every = span > 13 ? 3 : (span > 9 ? 2 : 1);
    int label_minor = (a->hi - a->lo) < 3.0;
    for (int d = d0; d <= d1 && n < cap; d++) {
      for (int m = 1; m <= 9 && n < cap; m++) {
        double u = d + log10((double)m);
        if (u < a->lo - 1e-9 || u > a->hi + 1e-9) continue;
        if (m > 1 && span > 6) continue; /* minors would clutter */
        t[n].v = m * pow(10, d);
        t[n].major = m == 1;
        t[n].labelled = (m == 1 && ((d % every) + every) % every == 0) || (label_minor && (m == 2 || m == 5));
        n++;
      }
    }
  } else {
    double span = a->hi - a->lo, raw = span / 6, mag = pow(10, floor(log10(raw))), step = mag;
    if (raw / mag > 5) step = 10 * mag;
    else if (raw / mag > 2) step = 5 * mag;
    else if (raw / mag > 1) step = 2 * mag;
    for (double v = ceil(a->lo / step - 1e-9) * step; v <= a->hi + 1e-9 * span && n < cap; v += step) {
      t[n].v = fabs(v) < 1e-12 * step ? 0 : v;
      t[n].major = 1;
      t[n].labelled = 1;
      n++;
    }
  }
  return n;
}

/* Splits `text` into lines no wider than `width` px at the current font. */
static int wrap(cairo_t *cr, const char *text, double width, char lines[][160], int cap) {
  int n = 0;
  char cur[160] = "";
  const char *p = text;
  while (*p && n < cap) {
    while (*p == ' ') p++;
    const char *q = p;
    while (*q && *q != ' ') q++;
    char word[160];
    size_t wl = (size_t)(q - p) < sizeof word - 1 ? (size_t)(q - p) : sizeof word - 1;
    memcpy(word, p, wl);
    word[wl] = 0;
    char trial[320];
    snprintf(trial, sizeof trial, "%s%s%s", cur, cur[0] ? " " : "", word);
    cairo_text_extents_t e;
    cairo_text_extents(cr, trial, &e);
    if (e.x_advance > width && cur[0]) {
      snprintf(lines[n++], 160, "%s", cur);
      snprintf(cur, sizeof cur, "%s", word);
    } else {
      snprintf(cur, sizeof cur, "%.159s", trial);
    }
    p = q;
  }
  if (cur[0] && n < cap) snprintf(lines[n++], 160, "%s", cur);
  return n;
}

/* ---- the chart ------------------------------------------------------------ */

typedef struct pt {
  double x, y;
} pt_t;

static int cmp_pt(const void *a, const void *b) {
  const pt_t *p = a, *q = b;
  if (p->x != q->x) return p->x < q->x ? -1 : 1;
  return (p->y > q->y) - (p->y < q->y);
}

/* Non-dominated points (minimal x and y) in increasing x; returns the count. */
static size_t pareto_front(const plot_t *p, const axis_t *ax, const axis_t *ay, pt_t **out) {
  size_t total = 0;
  for (int i = 0; i < p->nseries; i++)
    if (p->s[i].pareto) total += p->s[i].n;
  pt_t *all = malloc((total ? total : 1) * sizeof *all);
  if (!all) return 0;
  size_t k = 0;
  for (int i = 0; i < p->nseries; i++) {
    if (!p->s[i].pareto) continue;
    for (size_t j = 0; j < p->s[i].n; j++)
      if (drawable(ax, p->s[i].x[j]) && drawable(ay, p->s[i].y[j])) all[k++] = (pt_t){p->s[i].x[j], p->s[i].y[j]};
  }
  qsort(all, k, sizeof *all, cmp_pt);
  size_t m = 0;
  double best = INFINITY;
  for (size_t i = 0; i < k; i++)
    if (all[i].y < best) {
      best = all[i].y;
      all[m++] = all[i];
    }
  *out = all;
  return m;
}

int plot_write_png(const plot_t *p, const char *path, verr_t *err) {
  axis_t ax = {.log = p->logx}, ay = {.log = p->logy};
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  size_t npts = 0;
  for (int i = 0; i < p->nseries; i++)
    for (size_t j = 0; j < p->s[i].n; j++) {
      double x = p->s[i].x[j], y = p->s[i].y[j];
      if (!drawable(&ax, x) || !drawable(&ay, y)) continue;
      xmin = fmin(xmin, x), xmax = fmax(xmax, x), ymin = fmin(ymin, y), ymax = fmax(ymax, y);
      npts++;
    }
  if (!npts) return verr_set(err, "%s: no drawable point in any series", path);
  axis_fit(&ax, xmin, xmax);
  axis_fit(&ay, ymin, ymax);

  cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
  cairo_t *cr = cairo_create(surf);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_select_font_face(cr, FONT, CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);

  /* Legend width from its longest entry, at most a third of the image. */
  double lfont = 11.5;
  cairo_set_font_size(cr, lfont);
  double lw = 0;
  for (int i = 0; i < p->nseries; i++) {
    if (!p->s[i].label[0]) continue;
    const plot_series_t *s = &p->s[i];
    int any = 0;
    for (size_t j = 0; j < s->n; j++) any |= drawable(&ax, s->x[j]) && drawable(&ay, s->y[j]);
    char lab[160];
    snprintf(lab, sizeof lab, "%s%s", s->label, any ? "" : p->empty_suffix);
    cairo_text_extents_t e;
    cairo_text_extents(cr, lab, &e);
    lw = fmax(lw, e.x_advance);
  }
  lw = fmin(lw + 44, 320);
  if (lw < 170) lw = 170;
  double lx0 = W - lw - 8;

  /* Y tick label width decides the left margin. */
  tick_t tx[128], ty[128];
  double left_tmp = 80;
  ay.p0 = H - 62;
  ay.p1 = 46;
  int nty = make_ticks(&ay, ty, 128);
  double ytw = 0;
  for (int i = 0; i < nty; i++)
    if (ty[i].labelled) {
      ticklabel_t t = format_tick(ty[i].v, ay.log);
      ytw = fmax(ytw, tick_width(cr, &t, 12));
    }
  left_tmp = 40 + ytw + 10;
  ax.p0 = left_tmp;
  ax.p1 = lx0 - 18;
  int ntx = make_ticks(&ax, tx, 128);

  /* Title. */
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_select_font_face(cr, FONT, CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_font_size(cr, 15);
  {
    cairo_text_extents_t e;
    cairo_text_extents(cr, p->title, &e);
    double tsz = 15;
    while (e.x_advance > W - 20 && tsz > 9) {
      tsz -= 0.5;
      cairo_set_font_size(cr, tsz);
      cairo_text_extents(cr, p->title, &e);
    }
    cairo_move_to(cr, (W - e.x_advance) / 2, 27);
    cairo_show_text(cr, p->title);
  }
  cairo_select_font_face(cr, FONT, CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);

  double X0 = ax.p0, X1 = ax.p1, Y0 = ay.p0, Y1 = ay.p1;
  /* Grid, then ticks and labels. */
  for (int i = 0; i < ntx; i++) {
    double px = to_px(&ax, tx[i].v);
    grid_line(cr, tx[i].major, px, Y0, px, Y1);
  }
  for (int i = 0; i < nty; i++) {
    double py = to_px(&ay, ty[i].v);
    grid_line(cr, ty[i].major, X0, py, X1, py);
  }
  cairo_set_source_rgb(cr, 0, 0, 0);
  set_line(cr, PLOT_LINE_SOLID, 1.2);
  cairo_rectangle(cr, X0, Y1, X1 - X0, Y0 - Y1);
  cairo_stroke(cr);
  double last_right = -1e9;
  for (int i = 0; i < ntx; i++) {
    double px = to_px(&ax, tx[i].v), len = tx[i].major ? 7 : 4;
    set_line(cr, PLOT_LINE_SOLID, 1);
    cairo_move_to(cr, px, Y0);
    cairo_line_to(cr, px, Y0 - len);
    cairo_stroke(cr);
    if (!tx[i].labelled) continue;
    ticklabel_t t = format_tick(tx[i].v, ax.log);
    double w = tick_width(cr, &t, 12);
    if (px - w / 2 < last_right + 6) continue; /* never overprint */
    tick_draw(cr, &t, px - w / 2, Y0 + 18, 12);
    last_right = px + w / 2;
  }
  for (int i = 0; i < nty; i++) {
    double py = to_px(&ay, ty[i].v), len = ty[i].major ? 7 : 4;
    set_line(cr, PLOT_LINE_SOLID, 1);
    cairo_move_to(cr, X0, py);
    cairo_line_to(cr, X0 + len, py);
    cairo_stroke(cr);
    if (!ty[i].labelled) continue;
    ticklabel_t t = format_tick(ty[i].v, ay.log);
    double w = tick_width(cr, &t, 12);
    tick_draw(cr, &t, X0 - 6 - w, py + 4, 12);
  }
  /* Axis titles. */
  cairo_set_font_size(cr, 13.5);
  {
    cairo_text_extents_t e;
    cairo_text_extents(cr, p->xlabel, &e);
    cairo_move_to(cr, (X0 + X1 - e.x_advance) / 2, H - 20);
    cairo_show_text(cr, p->xlabel);
    cairo_text_extents(cr, p->ylabel, &e);
    cairo_save(cr);
    cairo_move_to(cr, 22, (Y0 + Y1 + e.x_advance) / 2);
    cairo_rotate(cr, -M_PI / 2);
    cairo_show_text(cr, p->ylabel);
    cairo_restore(cr);
  }

  /* Data, clipped to the frame. */
  cairo_save(cr);
  cairo_rectangle(cr, X0, Y1, X1 - X0, Y0 - Y1);
  cairo_clip(cr);
  pt_t *front = NULL;
  size_t nfront = p->pareto ? pareto_front(p, &ax, &ay, &front) : 0;
  if (nfront) {
    /* A wide pale staircase behind the data: everything above/right of it
     * is beaten by some configuration on it. */
    cairo_set_source_rgba(cr, 0.3, 0.3, 0.3, 0.28);
    set_line(cr, PLOT_LINE_SOLID, 7);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    cairo_move_to(cr, to_px(&ax, front[0].x), to_px(&ay, front[0].y));
    for (size_t i = 1; i < nfront; i++) {
      cairo_line_to(cr, to_px(&ax, front[i].x), to_px(&ay, front[i - 1].y));
      cairo_line_to(cr, to_px(&ax, front[i].x), to_px(&ay, front[i].y));
    }
    cairo_stroke(cr);
  }
  for (int i = 0; i < p->nseries; i++) {
    const plot_series_t *s = &p->s[i];
    if (s->line != PLOT_LINE_NONE) {
      set_colour(cr, s->color);
      set_line(cr, s->line, s->color < 0 ? 1.6 : 2.2);
      int pen = 0;
      for (size_t j = 0; j < s->n; j++) {
        if (!drawable(&ax, s->x[j]) || !drawable(&ay, s->y[j])) {
          pen = 0;
          continue;
        }
        double px = to_px(&ax, s->x[j]), py = to_px(&ay, s->y[j]);
        if (pen) cairo_line_to(cr, px, py);
        else cairo_move_to(cr, px, py);
        pen = 1;
      }
      cairo_stroke(cr);
    }
    if (s->marker >= 0) {
      set_colour(cr, s->color);
      for (size_t j = 0; j < s->n; j++)
        if (drawable(&ax, s->x[j]) && drawable(&ay, s->y[j])) marker(cr, s->marker, to_px(&ax, s->x[j]), to_px(&ay, s->y[j]), 4.2);
    }
    if (s->tag) {
      set_colour(cr, s->color);
      cairo_set_font_size(cr, 10.5);
      for (size_t j = 0; j < s->n; j++) {
        if (!drawable(&ax, s->x[j]) || !drawable(&ay, s->y[j])) continue;
        char t[24];
        snprintf(t, sizeof t, "%g", s->tag[j]);
        cairo_move_to(cr, to_px(&ax, s->x[j]) + 6, to_px(&ay, s->y[j]) - 7);
        cairo_show_text(cr, t);
      }
    }
  }
  if (nfront) {
    cairo_set_source_rgb(cr, 0, 0, 0);
    set_line(cr, PLOT_LINE_SOLID, 1.4);
    for (size_t i = 0; i < nfront; i++) {
      cairo_new_sub_path(cr);
      cairo_arc(cr, to_px(&ax, front[i].x), to_px(&ay, front[i].y), 8, 0, 2 * M_PI);
    }
    cairo_stroke(cr);
  }
  free(front);
  cairo_restore(cr);

  /* Legend, outside the frame on the right. */
  int nleg = 0;
  for (int i = 0; i < p->nseries; i++) nleg += p->s[i].label[0] != 0;
  nleg += nfront > 0;
  double row = 19;
  if (nleg * row > (Y0 - Y1) * 0.8) row = fmax(12, (Y0 - Y1) * 0.8 / nleg);
  double lf = fmin(lfont, row * 0.68);
  cairo_set_font_size(cr, lf);
  double ly = Y1 + 4, lx = lx0;
  cairo_set_source_rgb(cr, 0.97, 0.97, 0.97);
  cairo_rectangle(cr, lx - 4, ly - 2, lw + 4, nleg * row + 8);
  cairo_fill_preserve(cr);
  cairo_set_source_rgb(cr, 0.6, 0.6, 0.6);
  set_line(cr, PLOT_LINE_SOLID, 1);
  cairo_stroke(cr);
  for (int i = 0; i < p->nseries; i++) {
    const plot_series_t *s = &p->s[i];
    if (!s->label[0]) continue;
    double cy = ly + row * 0.5 + 2;
    set_colour(cr, s->color);
    if (s->line != PLOT_LINE_NONE) {
      set_line(cr, s->line, 2.2);
      cairo_move_to(cr, lx + 2, cy);
      cairo_line_to(cr, lx + 30, cy);
      cairo_stroke(cr);
    }
    if (s->marker >= 0) marker(cr, s->marker, lx + 16, cy, 4.2);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_move_to(cr, lx + 36, cy + lf * 0.36);
    char lab[160];
    int any = 0;
    for (size_t j = 0; j < s->n; j++) any |= drawable(&ax, s->x[j]) && drawable(&ay, s->y[j]);
    snprintf(lab, sizeof lab, "%s%s", s->label, any ? "" : p->empty_suffix);
    cairo_text_extents_t e;
    cairo_text_extents(cr, lab, &e);
    /* Labels too long for the box are shortened rather than overflowing. */
    while (e.x_advance > lw - 42 && strlen(lab) > 4) {
      size_t L = strlen(lab);
      lab[L - 4] = '.', lab[L - 3] = '.', lab[L - 2] = 0;
      cairo_text_extents(cr, lab, &e);
    }
    cairo_show_text(cr, lab);
    ly += row;
  }
  if (nfront) {
    double cy = ly + row * 0.5 + 2;
    cairo_set_source_rgba(cr, 0.3, 0.3, 0.3, 0.28);
    set_line(cr, PLOT_LINE_SOLID, 7);
    cairo_move_to(cr, lx + 2, cy);
    cairo_line_to(cr, lx + 30, cy);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    set_line(cr, PLOT_LINE_SOLID, 1.4);
    cairo_arc(cr, lx + 16, cy, 7, 0, 2 * M_PI);
    cairo_stroke(cr);
    cairo_move_to(cr, lx + 36, cy + lf * 0.36);
    cairo_show_text(cr, "Pareto front (ringed)");
    ly += row;
  }
  /* Notes, wrapped to the legend width, clear of the legend box. */
  ly += 24;
  cairo_set_font_size(cr, 10.5);
  cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
  for (int i = 0; i < p->nnotes; i++) {
    char lines[12][160];
    int nl = wrap(cr, p->notes[i], lw - 4, lines, 12);
    for (int k = 0; k < nl && ly < H - 8; k++) {
      cairo_move_to(cr, lx, ly);
      cairo_show_text(cr, lines[k]);
      ly += 13;
    }
    ly += 5;
  }

  cairo_destroy(cr);
  cairo_status_t st = cairo_surface_write_to_png(surf, path);
  cairo_surface_destroy(surf);
  if (st != CAIRO_STATUS_SUCCESS) return verr_set(err, "%s: cairo: %s", path, cairo_status_to_string(st));
  return 0;
}
