/* SPDX-License-Identifier: Apache-2.0 */
#include "charts.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "measure_table.h"
#include "plot/plot.h"
#include "plot/plot_bars.h"

/* Threshold colours match the viewer's force bar: orange above ST, red
 * above MPF; SFT, the hard stop, in black. */
static const int LEVEL_COLOR[THR_COUNT] = {1, 3, PLOT_BLACK};

int rep_chart_force(const rep_recording_t *r, const char *path, verr_t *err) {
  plot_t *p = calloc(1, sizeof *p);
  if (!p) return verr_set(err, "%s: out of memory", path);
  char title[160];
  snprintf(title, sizeof title, "%s: contact force%s%s", r->label, r->scene[0] ? ", scene " : "", r->scene);
  plot_init(p, title, "simulated time since the tool first reported (s)", "contact force |F| (N)", 0, 0);
  double t0 = INFINITY, t1 = -INFINITY, fmax_all = 0;
  for (int i = 0; i < r->ntools; i++)
    if (r->tools[i].nforce) {
      t0 = fmin(t0, r->tools[i].force[0].t);
      t1 = fmax(t1, r->tools[i].force[r->tools[i].nforce - 1].t);
    }
  if (!isfinite(t0)) {
    free(p);
    return verr_set(err, "%s: no force samples to draw", path);
  }
  int ret = 0;
  for (int i = 0; i < r->ntools && ret == 0; i++) {
    const rep_tool_t *t = &r->tools[i];
    if (!t->nforce) continue;
    /* room for a NAN break before every sample */
    double *x = malloc(2 * t->nforce * sizeof *x), *y = malloc(2 * t->nforce * sizeof *y);
    if (!x || !y) {
      ret = verr_set(err, "%s: out of memory", path);
    } else {
      /* A gap (tool released, samples lost) breaks the line instead of
       * drawing a straight segment across it. */
      size_t n = 0;
      for (size_t k = 0; k < t->nforce; k++) {
        if (k > 0 && t->force[k].t - t->force[k - 1].t > REP_GAP_S) {
          x[n] = t->force[k].t - t0;
          y[n++] = NAN;
        }
        x[n] = t->force[k].t - t0;
        y[n++] = t->force[k].force;
        fmax_all = fmax(fmax_all, t->force[k].force);
      }
      char lab[112];
      snprintf(lab, sizeof lab, "%s (peak %.2f N)", t->name, t->fm.peak_force);
      plot_add(p, lab, n, x, y, i == 0 ? 0 : 4 + i, -1, PLOT_LINE_SOLID);
    }
    free(x);
    free(y);
  }
  /* Threshold lines of the first tool that has them, across the plot. */
  for (int k = 0; k < THR_COUNT && ret == 0; k++) {
    double L = r->sum.levels[k];
    if (!(L > 0)) continue;
    double x[2] = {0, t1 - t0}, y[2] = {L, L};
    char lab[112];
    snprintf(lab, sizeof lab, "%s %.2f N (%s)", thr_name((thr_id_t)k), L, thr_long_name((thr_id_t)k));
    plot_add(p, lab, 2, x, y, LEVEL_COLOR[k], -1, k == THR_SFT ? PLOT_LINE_DOTTED : PLOT_LINE_DASHED);
  }
  /* Invisible anchor: the force axis starts at zero. */
  double ax[1] = {0}, ay[1] = {0};
  if (ret == 0) plot_add(p, "", 1, ax, ay, PLOT_GREY, -1, PLOT_LINE_NONE);
  if (ret == 0) {
    /* Only the levels the scene set: "0.00 s above SFT" of an unset SFT
     * would read as a trainee who stayed below it. */
    char above[160] = "";
    size_t len = 0;
    for (int k = 0; k < THR_COUNT; k++)
      if (r->sum.levels[k] > 0 && len < sizeof above)
        len += (size_t)snprintf(above + len, sizeof above - len, "%s above %s %.2f s", len ? "," : "time",
                                thr_name((thr_id_t)k), r->sum.time_above[k]);
    plot_note(p, "%s; in contact %.2f s", len ? above : "no thresholds set", r->sum.contact_time);
    ret = plot_write_png(p, path, err);
  }
  plot_free(p);
  free(p);
  return ret;
}

int rep_chart_force_overlay(const rep_recording_t *const *recs, int n, const char *path, verr_t *err) {
  plot_t *p = calloc(1, sizeof *p);
  if (!p) return verr_set(err, "%s: out of memory", path);
  plot_init(p, "contact force of every trainee", "simulated time since the trainee's first sample (s)",
            "contact force |F| (N), all tools", 0, 0);
  int ret = 0, drawn = 0;
  double tmax = 0;
  for (int i = 0; i < n && ret == 0 && i < PLOT_MAX_SERIES - THR_COUNT - 1; i++) {
    const rep_recording_t *r = recs[i];
    /* The busiest tool's samples give the time base; the force at each is
     * the sum over tools of their latest sample (one server step apart). */
    int base = -1;
    for (int t = 0; t < r->ntools; t++)
      if (r->tools[t].nforce && (base < 0 || r->tools[t].nforce > r->tools[base].nforce)) base = t;
    if (base < 0) continue;
    const rep_tool_t *b = &r->tools[base];
    double *x = malloc(2 * b->nforce * sizeof *x), *y = malloc(2 * b->nforce * sizeof *y);
    size_t cur[REP_MAX_TOOLS] = {0};
    if (!x || !y) {
      ret = verr_set(err, "%s: out of memory", path);
    } else {
      size_t m = 0;
      double t0 = b->force[0].t;
      for (size_t k = 0; k < b->nforce; k++) {
        double t = b->force[k].t, f = 0;
        for (int u = 0; u < r->ntools; u++) {
          const rep_tool_t *o = &r->tools[u];
          while (cur[u] + 1 < o->nforce && o->force[cur[u] + 1].t <= t) cur[u]++;
          if (o->nforce && o->force[cur[u]].t <= t && t - o->force[cur[u]].t <= REP_GAP_S) f += o->force[cur[u]].force;
        }
        if (k > 0 && t - b->force[k - 1].t > REP_GAP_S) x[m] = t - t0, y[m++] = NAN;
        x[m] = t - t0, y[m++] = f;
        tmax = fmax(tmax, t - t0);
      }
      char lab[112];
      snprintf(lab, sizeof lab, "%s (peak %.2f N)", r->label, r->sum.peak_force);
      /* palette colours other than the threshold lines' */
      static const int COL[] = {0, 2, 4, 5, 6, 7, 8, 9};
      int col = i < (int)(sizeof COL / sizeof COL[0]) ? COL[i] : i + 2;
      if (plot_add(p, lab, m, x, y, col, -1, PLOT_LINE_SOLID)) drawn++;
    }
    free(x);
    free(y);
  }
  if (ret == 0 && !drawn) ret = verr_set(err, "%s: no force samples to draw", path);
  for (int k = 0; k < THR_COUNT && ret == 0; k++) {
    double L = recs[0]->sum.levels[k];
    if (!(L > 0)) continue;
    double x[2] = {0, tmax}, y[2] = {L, L};
    char lab[112];
    snprintf(lab, sizeof lab, "%s %.2f N", thr_name((thr_id_t)k), L);
    plot_add(p, lab, 2, x, y, LEVEL_COLOR[k], -1, k == THR_SFT ? PLOT_LINE_DOTTED : PLOT_LINE_DASHED);
  }
  double ax[1] = {0}, ay[1] = {0};
  if (ret == 0) plot_add(p, "", 1, ax, ay, PLOT_GREY, -1, PLOT_LINE_NONE);
  if (ret == 0) ret = plot_write_png(p, path, err);
  plot_free(p);
  free(p);
  return ret;
}

int rep_chart_compare(const rep_recording_t *const *recs, int n, int measure, const char *path, verr_t *err) {
  const rep_measure_def_t *d = rep_measure(measure);
  if (!d) return verr_set(err, "%s: no measure %d", path, measure);
  plot_bars_t b;
  char ylabel[112];
  snprintf(ylabel, sizeof ylabel, "%s%s%s%s", d->title, d->unit[0] ? " (" : "", d->unit, d->unit[0] ? ")" : "");
  plot_bars_init(&b, d->title, ylabel, d->format);
  b.integer_axis = !d->unit[0]; /* unitless measures are counts */
  for (int i = 0; i < n && i < PLOT_BARS_MAX; i++)
    plot_bars_add(&b, recs[i]->label, rep_measure_value(recs[i], measure), i);
  return plot_bars_write_png(&b, path, 440, 300, err);
}
