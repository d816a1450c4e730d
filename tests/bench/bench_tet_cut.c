/* SPDX-License-Identifier: Apache-2.0 */
/* bench_tet_cut: progressive cutting on the spleen-size XPBD model, in the
 * style of docs/methods.md C Table 1 (vertices, elements, physics ms, topology update
 * ms, intersection ms), then 100 random incisions
 * (tests/stability/cut_scenario.h: the model and the cuts): time per cut,
 * element count and minimum quality after each.
 *
 * Table 1 columns: physics = median model step (dt 5 ms, one sub-step, 10
 * iterations) on the uncut mesh and after all cuts; intersection = mean per
 * blade call of the sweep against the tetrahedra; topology = mean per blade
 * call of splitting + opening + rebuilding the solver and the surface (the
 * seed's "topology update" includes intersection; here they are separate).
 * One core, this build's flags, machine possibly shared.
 *
 * usage: bench_tet_cut SOURCE_DIR [--cuts N] [--quick] [--csv OUT.csv] [--png OUT.png] */
#include <cairo.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cut_scenario.h"
#include "test_assets.h"

#if defined(__SANITIZE_ADDRESS__)
/* cairo's text drawing loads fontconfig's configuration once and keeps it
 * until exit, which LeakSanitizer reports; only allocations made from within
 * libfontconfig are matched. */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) { return "leak:libfontconfig.so\n"; }
const char *__lsan_default_options(void);
const char *__lsan_default_options(void) { return "print_suppressions=0"; }
#endif

#define CALLS_PER_CUT 8.0 /* 7 blade positions + the end */

static double median(double *v, int n) {
  for (int i = 1; i < n; i++)
    for (int j = i; j > 0 && v[j] < v[j - 1]; j--) {
      double t = v[j];
      v[j] = v[j - 1];
      v[j - 1] = t;
    }
  return n ? v[n / 2] : NAN;
}

static double step_median(model_t *m, int steps) {
  double *t = malloc((size_t)steps * sizeof *t);
  for (int k = 0; k < steps; k++) {
    uint64_t a = vtime_mono_ns();
    m->ops->step(m, CUT_DT);
    t[k] = (double)(vtime_mono_ns() - a) * 1e-6;
  }
  double r = median(t, steps);
  free(t);
  return r;
}

/* One panel: y against cut number, linear or log y. */
static void panel(cairo_t *cr, double x0, double y0, double w, double h, const char *title, const double *y, int n,
                  int logy, double r, double g, double b) {
  double lo = INFINITY, hi = -INFINITY;
  for (int i = 0; i < n; i++) {
    double v = logy ? log10(fmax(y[i], 1e-9)) : y[i];
    lo = fmin(lo, v);
    hi = fmax(hi, v);
  }
  if (!logy) lo = fmin(lo, 0);
  if (logy) {
    lo = floor(lo);
    hi = ceil(hi);
  }
  if (!(hi > lo)) hi = lo + 1;
  double px = x0 + 60, py = y0 + 30, pw = w - 80, ph = h - 60;
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 1);
  cairo_rectangle(cr, px, py, pw, ph);
  cairo_stroke(cr);
  cairo_set_font_size(cr, 13);
  cairo_move_to(cr, px, y0 + 20);
  cairo_show_text(cr, title);
  cairo_set_font_size(cr, 10);
  char lab[64];
  for (int k = 0; k <= 4; k++) {
    double v = lo + (hi - lo) * k / 4, yy = py + ph - ph * k / 4;
    if (logy)
      snprintf(lab, sizeof lab, "%.2g", pow(10, v));
    else
      snprintf(lab, sizeof lab, "%.4g", v);
    cairo_move_to(cr, x0 + 2, yy + 3);
    cairo_show_text(cr, lab);
    cairo_set_source_rgb(cr, 0.85, 0.85, 0.85);
    cairo_move_to(cr, px, yy);
    cairo_line_to(cr, px + pw, yy);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
  }
  for (int k = 0; k <= 5; k++) {
    snprintf(lab, sizeof lab, "%d", (int)lround((double)n * k / 5));
    cairo_move_to(cr, px + pw * k / 5 - 6, py + ph + 14);
    cairo_show_text(cr, lab);
  }
  cairo_move_to(cr, px + pw / 2 - 20, py + ph + 27);
  cairo_show_text(cr, "cuts");
  cairo_set_source_rgb(cr, r, g, b);
  cairo_set_line_width(cr, 1.5);
  for (int i = 0; i < n; i++) {
    double v = logy ? log10(fmax(y[i], 1e-9)) : y[i];
    double xx = px + pw * (i + 1) / n, yy = py + ph - ph * (v - lo) / (hi - lo);
    if (i == 0)
      cairo_move_to(cr, xx, yy);
    else
      cairo_line_to(cr, xx, yy);
  }
  cairo_stroke(cr);
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: bench_tet_cut SOURCE_DIR [--cuts N] [--quick] [--csv OUT.csv] [--png OUT.png]\n");
    return 2;
  }
  int cuts = 100;
  const char *csv_path = NULL, *png_path = NULL;
  for (int i = 2; i < argc; i++) {
    if (!strcmp(argv[i], "--quick"))
      cuts = 10;
    else if (!strcmp(argv[i], "--cuts") && i + 1 < argc)
      cuts = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--csv") && i + 1 < argc)
      csv_path = argv[++i];
    else if (!strcmp(argv[i], "--png") && i + 1 < argc)
      png_path = argv[++i];
    else {
      fprintf(stderr, "bench_tet_cut: unknown option %s\n", argv[i]);
      return 2;
    }
  }
  if (cuts < 1 || cuts > 100000) {
    fprintf(stderr, "bench_tet_cut: --cuts must be 1..100000\n");
    return 2;
  }
  mesh_t surf;
  scene_organ_t cfg;
  verr_t err;
  char assets[2048];
  snprintf(assets, sizeof assets, "%s/assets", argv[1]);
  test_assets_dir_set(assets);
  model_t *m = cut_spleen_model(&surf, &cfg, &err);
  if (!m) {
    fprintf(stderr, "bench_tet_cut: %s\n", err.msg);
    return 1;
  }
  tet_model_cut_t *tc = tet_model_cut_create(m, &err);
  if (!tc) {
    fprintf(stderr, "bench_tet_cut: %s\n", err.msg);
    return 1;
  }
  pbd_t *s = model_pbd_solver(m);
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < s->n; i++)
    for (int k = 0; k < 3; k++) {
      lo[k] = fmin(lo[k], s->x_rest[3 * i + k]);
      hi[k] = fmax(hi[k], s->x_rest[3 * i + k]);
    }
  size_t nodes0 = s->n, tets0 = s->ntets;
  double phys0 = step_median(m, 200);
  cut_record_t *rec = calloc((size_t)cuts, sizeof *rec);
  double *tets = malloc((size_t)cuts * sizeof(double)), *q = malloc((size_t)cuts * sizeof(double)),
         *ms = malloc((size_t)cuts * sizeof(double));
  unsigned seed = 20261121u;
  double isum = 0, tsum = 0;
  FILE *csv = csv_path ? fopen(csv_path, "w") : NULL;
  if (csv_path && !csv) fprintf(stderr, "bench_tet_cut: cannot write %s\n", csv_path);
  if (csv)
    fprintf(csv, "cut,nodes,tets,surf_tris,min_quality_rest,min_quality_now,cut_ms,intersect_ms,topology_ms,rebuild_ms,"
                 "step_ms,finite\n");
  for (int k = 0; k < cuts; k++) {
    cut_random(m, tc, lo, hi, &seed, &rec[k]);
    const cut_record_t *r = &rec[k];
    tets[k] = (double)r->tets;
    q[k] = r->min_q_rest;
    ms[k] = r->cut_ms;
    isum += r->intersect_ms;
    tsum += r->topology_ms + r->rebuild_ms;
    if (csv)
      fprintf(csv, "%d,%zu,%zu,%zu,%.6g,%.6g,%.4f,%.4f,%.4f,%.4f,%.4f,%d\n", k + 1, r->nodes, r->tets, r->surf_tris,
              r->min_q_rest, r->min_q_now, r->cut_ms, r->intersect_ms, r->topology_ms, r->rebuild_ms, r->step_ms,
              r->finite);
  }
  if (csv) fclose(csv);
  s = model_pbd_solver(m);
  const tet_cut_t *c = tet_model_cut_mesh(tc);
  double phys1 = step_median(m, 50);
  double calls = CALLS_PER_CUT * cuts;
  printf("bench_tet_cut: docs/methods.md C Table 1 style, spleen (assets/meshes/spleen.obj, tetrahedra of 7 mm), XPBD, "
         "dt %.0f ms, "
         "1 sub-step x 10 iterations\n",
         1e3 * CUT_DT);
  printf("%-22s %7s %7s %11s %13s %15s\n", "model", "nodes", "tets", "physics_ms", "topology_ms", "intersection_ms");
  printf("%-22s %7zu %7zu %11.3f %13s %15s\n", "spleen uncut", nodes0, tets0, phys0, "-", "-");
  printf("%-22s %7zu %7zu %11.3f %13.3f %15.3f\n", "spleen cutting", c->n, c->ntets, phys1, tsum / calls, isum / calls);
  printf(
      "(docs/methods.md C, GTX 580 + Xeon 2.53 GHz: spleen 711 nodes, 2385 elements, physics 1.2 ms, topology 3.2 ms, "
      "intersection 2.9 ms)\n\n");
  double *cm = malloc((size_t)cuts * sizeof(double));
  memcpy(cm, ms, (size_t)cuts * sizeof(double));
  double med = median(cm, cuts), p95 = cm[(int)(0.95 * (cuts - 1))], mx = cm[cuts - 1];
  size_t maxg = 0, prev = tets0;
  for (int k = 0; k < cuts; k++) {
    if (rec[k].tets - prev > maxg) maxg = rec[k].tets - prev;
    prev = rec[k].tets;
  }
  int finite = 1;
  for (int k = 0; k < cuts; k++) finite &= rec[k].finite;
  printf("%d random incisions: time per cut (8 blade calls incl. rebuilds) median %.1f ms, p95 %.1f, max %.1f; "
         "elements %zu -> %zu (mean growth %.0f, max %zu per cut); min rest quality %.4f; splits G1 %zu G2 %zu P1 %zu "
         "P2 %zu P3 %zu; %zu node copies; all finite: %s\n",
         cuts, med, p95, mx, tets0, c->ntets, (double)(c->ntets - tets0) / cuts, maxg, q[cuts - 1],
         c->stats.split_general[0], c->stats.split_general[1], c->stats.split_partial[0], c->stats.split_partial[1],
         c->stats.split_partial[2], c->stats.duplicated, finite ? "yes" : "NO");
  free(cm);
  if (png_path) {
    cairo_surface_t *sf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, 1200, 420);
    cairo_t *cr = cairo_create(sf);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    panel(cr, 0, 0, 400, 400, "tetrahedra after each cut", tets, cuts, 0, 0.1, 0.3, 0.8);
    panel(cr, 400, 0, 400, 400, "min rest quality (radius ratio, log)", q, cuts, 1, 0.8, 0.2, 0.1);
    panel(cr, 800, 0, 400, 400, "time per cut, ms", ms, cuts, 0, 0.1, 0.6, 0.2);
    cairo_destroy(cr);
    if (cairo_surface_write_to_png(sf, png_path) != CAIRO_STATUS_SUCCESS)
      fprintf(stderr, "bench_tet_cut: cannot write %s\n", png_path);
    cairo_surface_destroy(sf);
  }
  free(rec);
  free(tets);
  free(q);
  free(ms);
  tet_model_cut_destroy(tc);
  model_destroy(m);
  mesh_free(&surf);
  return finite ? 0 : 1;
}
