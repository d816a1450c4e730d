/* SPDX-License-Identifier: Apache-2.0 */
/* bench_ms_cut: three-stage mass-spring cutting (docs/methods.md D) on the tissue
 * block (45 v) and the gallbladder (5,393 v).
 *
 *  1. Incision width over time after a straight cut (the seed's Fig. 6):
 *     the whole stroke as one segment, so t = 0 is the moment the springs
 *     are cut; eps_r 0.2, 0.1, 0.05 and 0 (no residual stress).
 *  2. Cost: a straight stroke at 0.1 m/s with the default segments (4 mean
 *     edges): time of each topology change (the three stages, the rebuild
 *     and the stability re-estimate), of ms_cut_step without a change (the
 *     blade-surface crossing), and of a model step before and after the cut
 *     (sub-steps re-chosen).
 * Prints tables, writes ms_cut_width.csv, ms_cut_timing.csv and one PNG per
 * mesh (width over time) into --out DIR (default out/ms_cut). --quick: short
 * runs for the smoke test. Meshes: $VISCERA_SOURCE_DIR/assets/meshes (default:
 * the source tree it was built from). Wall-clock figures are printed, never
 * asserted. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "ms_cut_fixture.h"
#include "plot/plot.h"
#include "plot/plot_cleanup.h"
#include "vstats.h"
#include "vtime.h"

/* Width runs: scene-default stiffness (30 N/m edges and home springs), a
 * 1 kg organ, and damping set per mesh for the same damping ratios (home
 * springs 0.06, edges 0.03: those of the unit test's sheet), since the
 * node mass, and with it the time scale, differs 100-fold between the
 * meshes. c = 2 zeta sqrt(k m_node). */
static fx_material_t width_material(size_t nverts) {
  double m = 1.0 / (double)nverts, s = sqrt(30 * m);
  return (fx_material_t){1.0, 30, 2 * 0.03 * s, 30, 2 * 0.06 * s};
}

typedef struct organ {
  const char *name, *file;
  mesh_t mesh;
  double a[2], b[2], z; /* an interior straight cut on the top surface */
  int every;            /* width sample interval, steps (ms) */
} organ_t;

static int setup(organ_t *o) {
  if (test_mesh_load(o->file, &o->mesh)) return -1;
  double lo[3], hi[3];
  mesh_bounds(&o->mesh, lo, hi);
  double cx = 0.5 * (lo[0] + hi[0]), cy = 0.5 * (lo[1] + hi[1]), L = 0.3 * (hi[0] - lo[0]);
  /* Off the mesh's symmetry lines, so the blade does not run along edges. */
  o->a[0] = cx - L;
  o->a[1] = cy + 0.0011;
  o->b[0] = cx + L;
  o->b[1] = cy + 0.0011;
  o->z = hi[2];
  return 0;
}

/* Width over time: n samples every `every` steps. Returns lip nodes measured. */
static size_t width_run(organ_t *o, double eps_r, int n, int every, double *t, double *w) {
  verr_t err;
  model_t *m = fx_model(&o->mesh, width_material(o->mesh.nverts), "symplectic_euler", 1e-3, &err);
  if (!m) {
    printf("%s: %s\n", o->name, err.msg);
    return 0;
  }
  ms_cut_params_t p = ms_cut_default_params();
  p.eps_r = eps_r;
  p.segment_length = 1.0;
  ms_cut_t *c = ms_cut_create(m, &p, &err);
  size_t measured = 0;
  if (c && fx_stroke(m, c, o->a, o->b, o->z, 0.001, 0.5, 1e-3, NULL, NULL) > 0) {
    for (int i = 0; i < n; i++) {
      for (int s = 0; s < every; s++) m->ops->step(m, 1e-3);
      t[i] = (i + 1) * every * 1e-3;
      measured = ms_cut_incision_width(c, &w[i], NULL);
    }
  }
  ms_cut_destroy(c);
  model_destroy(m);
  return measured;
}

typedef struct timing {
  int segments;
  vstats_summary_t seg_ms, step_cut_us, model_before_us, model_after_us;
  int sub_before, sub_after, sub_max;
  size_t v_before, v_after, t_before, t_after;
  double total_cut_ms;
} timing_t;

static vstats_summary_t time_model(model_t *m, int steps) {
  double *v = malloc((size_t)steps * sizeof *v);
  for (int s = 0; s < steps; s++) {
    uint64_t t0 = vtime_mono_ns();
    m->ops->step(m, 1e-3);
    v[s] = (double)(vtime_mono_ns() - t0) * 1e-3;
  }
  vstats_summary_t r = vstats_summarise(v, (size_t)steps);
  free(v);
  return r;
}

static int timing_run(organ_t *o, int model_steps, timing_t *T) {
  verr_t err;
  memset(T, 0, sizeof *T);
  model_t *m = fx_model(&o->mesh, FX_DEFAULT_MATERIAL, "symplectic_euler", 1e-3, &err);
  if (!m) {
    printf("%s: %s\n", o->name, err.msg);
    return -1;
  }
  ms_cut_t *c = ms_cut_create(m, NULL, &err);
  if (!c) {
    printf("%s: %s\n", o->name, err.msg);
    model_destroy(m);
    return -1;
  }
  T->sub_before = m->substeps;
  T->v_before = m->nsurf;
  T->t_before = m->nsurf_tris;
  T->model_before_us = time_model(m, model_steps);
  double len = hypot(o->b[0] - o->a[0], o->b[1] - o->a[1]);
  long steps = (long)ceil(len / (0.1 * 1e-3));
  double *seg = malloc((size_t)(steps + 2) * sizeof *seg), *plain = malloc((size_t)(steps + 2) * sizeof *plain);
  size_t nseg = 0, nplain = 0;
  for (long s = 0; s <= steps + 1; s++) {
    double f = (double)(s > steps ? steps : s) / (double)steps;
    double x = o->a[0] + f * (o->b[0] - o->a[0]), y = o->a[1] + f * (o->b[1] - o->a[1]);
    double p0[3] = {x, y, o->z + 0.02}, p1[3] = {x, y, o->z - 0.02};
    uint64_t t0 = vtime_mono_ns();
    int rc = s <= steps ? ms_cut_step(c, p0, p1, 0.001, &err) : ms_cut_end(c, &err);
    double us = (double)(vtime_mono_ns() - t0) * 1e-3;
    if (rc < 0) {
      printf("%s: %s\n", o->name, err.msg);
      break;
    }
    if (rc == 1)
      seg[nseg++] = us * 1e-3;
    else if (s <= steps)
      plain[nplain++] = us;
    if (s <= steps) m->ops->step(m, 1e-3);
    if (m->substeps > T->sub_max) T->sub_max = m->substeps;
  }
  /* The blade lifted: ms_cut_step goes on each step and finishes the
   * stability re-estimate (model.h edit->refine). */
  for (int s = 0; s < 20; s++) {
    double up0[3] = {o->b[0], o->b[1], o->z + 1.0}, up1[3] = {o->b[0], o->b[1], o->z + 0.9};
    if (ms_cut_step(c, up0, up1, 0.001, &err) < 0) printf("%s: %s\n", o->name, err.msg);
    m->ops->step(m, 1e-3);
  }
  for (size_t i = 0; i < nseg; i++) T->total_cut_ms += seg[i];
  T->segments = (int)nseg;
  T->seg_ms = vstats_summarise(seg, nseg);
  T->step_cut_us = vstats_summarise(plain, nplain);
  T->sub_after = m->substeps;
  T->v_after = m->nsurf;
  T->t_after = m->nsurf_tris;
  T->model_after_us = time_model(m, model_steps);
  free(seg);
  free(plain);
  ms_cut_destroy(c);
  model_destroy(m);
  return 0;
}

int main(int argc, char **argv) {
  const char *out = "out/ms_cut";
  int quick = 0;
#ifdef MSCUT_SOURCE_DIR
  setenv("VISCERA_SOURCE_DIR", MSCUT_SOURCE_DIR, 0); /* the meshes of this source tree unless told otherwise */
#endif
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--quick"))
      quick = 1;
    else if (!strcmp(argv[i], "--out") && i + 1 < argc)
      out = argv[++i];
    else {
      fprintf(stderr, "usage: bench_ms_cut [--quick] [--out DIR]\n");
      return 2;
    }
  }
  /* cairo and fontconfig keep their font caches until exit; released then
   * on every return path so the sanitizer build's leak check stays clean. */
  atexit(plot_cleanup);
  char cmd[4200];
  snprintf(cmd, sizeof cmd, "mkdir -p '%s'", out);
  if (system(cmd) != 0) {
    fprintf(stderr, "cannot create %s\n", out);
    return 1;
  }
  organ_t organs[2] = {{.name = "tissue_block", .file = "tissue_block.obj", .every = 4},
                       {.name = "gallbladder", .file = "gallbladder.obj", .every = 1}};
  for (int k = 0; k < 2; k++)
    if (setup(&organs[k])) return 1;

  /* 1. Width over time. */
  const double eps[4] = {0.2, 0.1, 0.05, 0.0};
  const int n = quick ? 50 : 400; /* samples: 1.6 s on the block, 0.4 s on the gallbladder */
  char path[4300];
  snprintf(path, sizeof path, "%s/ms_cut_width.csv", out);
  FILE *csv = fopen(path, "w");
  if (!csv) {
    fprintf(stderr, "cannot write %s\n", path);
    return 1;
  }
  fprintf(csv, "organ,eps_r,t_s,width_mm\n");
  printf("Incision width after a straight interior cut (docs/methods.md D Fig. 6): 1 kg organ, k 30 N/m, home 30 N/m, "
         "damping ratios 0.03 (edges) and 0.06 (home springs), blade radius 1 mm, symplectic Euler at 1 kHz\n\n");
  printf("| organ | eps_r | lip nodes | first sample | peak (time) | final (mean of last 20 %%) | final / peak |\n");
  printf("|---|---|---|---|---|---|---|\n");
  for (int k = 0; k < 2; k++) {
    organ_t *o = &organs[k];
    const int every = o->every;
    fx_material_t wm = width_material(o->mesh.nverts);
    plot_t pl;
    char title[160];
    snprintf(title, sizeof title, "Incision width after a straight cut: %s (%zu vertices)", o->name, o->mesh.nverts);
    plot_init(&pl, title, "time after the cut (s)", "incision width (mm)", 0, 0);
    for (int e = 0; e < 4; e++) {
      double t[400], w[400];
      memset(w, 0, sizeof w);
      size_t lips = width_run(o, eps[e], n, every, t, w);
      int ip = 0;
      for (int i = 0; i < n; i++) {
        w[i] *= 1e3;
        fprintf(csv, "%s,%g,%.4f,%.6f\n", o->name, eps[e], t[i], w[i]);
        if (w[i] > w[ip]) ip = i;
      }
      int tail = n / 5;
      double fin = 0;
      for (int i = n - tail; i < n; i++) fin += w[i] / tail;
      printf("| %s | %.2f | %zu | %.4f mm | %.4f mm (%.0f ms) | %.4f mm | %.2f |\n", o->name, eps[e], lips, w[0], w[ip],
             t[ip] * 1e3, fin, w[ip] > 0 ? fin / w[ip] : NAN);
      char lab[64];
      snprintf(lab, sizeof lab, "eps_r = %.2f%s", eps[e], eps[e] == 0 ? " (no residual stress)" : "");
      plot_add(&pl, lab, (size_t)n, t, w, e == 3 ? PLOT_GREY : e, -1, PLOT_LINE_SOLID);
    }
    plot_note(&pl, "Width: mean distance from each lip node of one side to the other side's lip.");
    plot_note(
        &pl, "Residual stress sigma_r = E eps_r as nodal force eps_r K L0 per cut spring (docs/methods.md D eq. 3-4).");
    plot_note(&pl, "Material: mass %.1f kg, k %.0f N/m, damping %.3g, home %.0f / %.3g N s/m; blade radius 1 mm.",
              wm.mass, wm.stiffness, wm.damping, wm.home_stiffness, wm.home_damping);
    snprintf(path, sizeof path, "%s/ms_cut_width_%s.png", out, o->name);
    verr_t err;
    if (plot_write_png(&pl, path, &err)) printf("plot: %s\n", err.msg);
    plot_free(&pl);
  }
  fclose(csv);

  /* 2. Cost. */
  snprintf(path, sizeof path, "%s/ms_cut_timing.csv", out);
  csv = fopen(path, "w");
  if (!csv) return 1;
  fprintf(csv,
          "organ,vertices_before,vertices_after,triangles_before,triangles_after,segments,segment_ms_median,"
          "segment_ms_max,cut_total_ms,step_cut_us_median,step_cut_us_p99,substeps_before,substeps_max,substeps_after,"
          "model_step_us_before,model_step_us_after\n");
  printf("\nCost of a straight stroke at 0.1 m/s (default material, blade radius 1 mm, segments of 4 mean edges), "
         "one core, %s build\n\n",
#ifdef NDEBUG
         "optimised"
#else
         "debug"
#endif
  );
  printf(
      "| organ | vertices before -> after | segments | per segment median / max | cut work total | "
      "ms_cut_step without change median / p99 | sub-steps before -> max during -> after | model step median before -> "
      "after |\n");
  printf("|---|---|---|---|---|---|---|---|\n");
  for (int k = 0; k < 2; k++) {
    timing_t T;
    if (timing_run(&organs[k], quick ? 50 : 1000, &T)) continue;
    printf("| %s | %zu -> %zu | %d | %.2f / %.2f ms | %.1f ms | %.1f / %.1f us | %d -> %d -> %d | %.0f -> %.0f us |\n",
           organs[k].name, T.v_before, T.v_after, T.segments, T.seg_ms.median, T.seg_ms.max, T.total_cut_ms,
           T.step_cut_us.median, T.step_cut_us.p99, T.sub_before, T.sub_max, T.sub_after, T.model_before_us.median,
           T.model_after_us.median);
    fprintf(csv, "%s,%zu,%zu,%zu,%zu,%d,%.4f,%.4f,%.3f,%.3f,%.3f,%d,%d,%d,%.2f,%.2f\n", organs[k].name, T.v_before,
            T.v_after, T.t_before, T.t_after, T.segments, T.seg_ms.median, T.seg_ms.max, T.total_cut_ms,
            T.step_cut_us.median, T.step_cut_us.p99, T.sub_before, T.sub_max, T.sub_after, T.model_before_us.median,
            T.model_after_us.median);
  }
  fclose(csv);
  printf("\nwrote %s/ms_cut_width.csv, %s/ms_cut_timing.csv, %s/ms_cut_width_*.png\n", out, out, out);
  for (int k = 0; k < 2; k++) mesh_free(&organs[k].mesh);
  return 0;
}
