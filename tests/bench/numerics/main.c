/* SPDX-License-Identifier: Apache-2.0 */
/* bench_numerics: error against run time and stability for every
 * deformation model and integrator (docs/numerics.md §1-§4).
 *
 * usage: bench_numerics [--quick] [--out DIR] [--assets DIR] [--only LIST]
 *   --only spring,chain,cloth,stability,bar,ball,probe,incision,scaling   run some scene families
 *
 * Writes one CSV per sweep and the PNG charts into DIR (default
 * out/numerics), prints progress on stderr and a summary table on stdout.
 * Every scene is built in code; only S8 reads assets/meshes/spleen.obj (and
 * the scaling plot the other organ meshes). Timing is single-threaded (one
 * core), double precision, with the compiler flags printed in the header.
 * --quick shortens every sweep so the whole run stays under a minute (the
 * ctest smoke test); the figures are then coarser, not different. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "numerics.h"
#include "plot/plot_cleanup.h"
#include "vtime.h"

#ifndef NUMERICS_SOURCE_DIR
#define NUMERICS_SOURCE_DIR "."
#endif
#ifndef NUMERICS_C_FLAGS
#define NUMERICS_C_FLAGS "?"
#endif
#ifndef NUMERICS_BUILD_TYPE
#define NUMERICS_BUILD_TYPE "?"
#endif

static int mkdir_p(const char *path) {
  char buf[1024];
  snprintf(buf, sizeof buf, "%s", path);
  for (char *p = buf + 1; *p; p++) {
    if (*p != '/') continue;
    *p = 0;
    if (mkdir(buf, 0777) && errno != EEXIST) return -1;
    *p = '/';
  }
  if (mkdir(buf, 0777) && errno != EEXIST) return -1;
  return 0;
}

static void cpu_name(char *out, size_t cap) {
  snprintf(out, cap, "unknown CPU");
  FILE *f = fopen("/proc/cpuinfo", "r");
  if (!f) return;
  char line[512];
  while (fgets(line, sizeof line, f)) {
    if (strncmp(line, "model name", 10)) continue;
    char *c = strchr(line, ':');
    if (!c) break;
    c++;
    while (*c == ' ') c++;
    c[strcspn(c, "\n")] = 0;
    snprintf(out, cap, "%s", c);
    break;
  }
  fclose(f);
}

static int same_group(const nb_row_t *a, const nb_row_t *b) {
  return !strcmp(a->scene, b->scene) && !strcmp(a->model, b->model) && !strcmp(a->integ, b->integ);
}

static void print_row(const nb_row_t *r, const char *why) {
  char e[16], ee[16], us[16], ms[16];
  if (isfinite(r->err)) snprintf(e, sizeof e, "%.2e", r->err);
  else if (strstr(r->metric, "other_mesh")) snprintf(e, sizeof e, "other mesh"); /* S9: cut differently */
  else snprintf(e, sizeof e, "%s", strcmp(r->metric, "timing") ? "unstable" : "-");
  if (isfinite(r->err_end)) snprintf(ee, sizeof ee, "%.2e", r->err_end);
  else snprintf(ee, sizeof ee, "-");
  if (isfinite(r->step_us)) snprintf(us, sizeof us, "%.4g", r->step_us);
  else snprintf(us, sizeof us, "-");
  if (isfinite(r->sim_ms)) snprintf(ms, sizeof ms, "%.4g", r->sim_ms);
  else snprintf(ms, sizeof ms, "-");
  printf("%-4s %-20s %-17s %-26s %-13s %9s %9s %9s %10s  %s\n", r->scene, r->model, r->integ, r->setting, r->metric, e,
         ee, us, ms, why);
}

/* The table docs/numerics.md §7 asks about: per scene, model and integrator, the
 * 60 Hz setting (the interactive one) and the cheapest setting whose error is
 * at most 1 % (the accurate one), or the most accurate one when none is;
 * model-error and timing rows as they are. Every row is in summary.csv. */
static void print_summary(const nb_t *nb) {
  printf("\n%-4s %-20s %-17s %-26s %-13s %9s %9s %9s %10s  %s\n", "scn", "model", "integrator", "setting", "metric",
         "err_max", "err_end", "us/step", "ms/sim-s", "selected as");
  for (size_t i = 0; i < nb->nrows; i++) {
    const nb_row_t *ri = &nb->rows[i];
    if (!strcmp(ri->metric, "rel_model_err")) {
      print_row(ri, "model error (static)");
      continue;
    }
    if (!strcmp(ri->metric, "timing")) {
      print_row(ri, "timing");
      continue;
    }
    int first = 1;
    for (size_t j = 0; j < i; j++)
      if (same_group(ri, &nb->rows[j]) && strcmp(nb->rows[j].metric, "timing")) first = 0;
    if (!first) continue;
    const nb_row_t *r60 = NULL, *acc = NULL, *best = NULL;
    for (size_t j = i; j < nb->nrows; j++) {
      const nb_row_t *r = &nb->rows[j];
      if (!same_group(r, ri) || !strcmp(r->metric, "timing")) continue;
      if (fabs(r->dt - 1.0 / 60) < 1e-9 && (!r60 || r->sim_ms < r60->sim_ms)) r60 = r;
      if (r->err <= 0.01 && (!acc || r->sim_ms < acc->sim_ms)) acc = r;
      if (isfinite(r->err) && (!best || r->err < best->err)) best = r;
    }
    if (r60)
      print_row(r60, isfinite(r60->err) ? "60 Hz"
                     : strstr(r60->metric, "other_mesh") ? "60 Hz (cut another mesh than the reference)"
                                                         : "60 Hz (diverged)");
    if (acc && acc != r60) print_row(acc, "cheapest with err <= 1%");
    if (!acc && best && best != r60) print_row(best, "most accurate (none <= 1%)");
    if (!best && !r60) print_row(ri, "diverged at every setting");
    else if (!best) printf("%-4s %-20s %-17s   (diverged at every setting tried)\n", ri->scene, ri->model, ri->integ);
  }
}

/* 1 when `name` is in the comma-separated list (or there is no list). */
static int wanted(const char *only, const char *name) {
  if (!only) return 1;
  size_t n = strlen(name);
  for (const char *p = only; (p = strstr(p, name)); p += n)
    if ((p == only || p[-1] == ',') && (p[n] == 0 || p[n] == ',')) return 1;
  return 0;
}

int main(int argc, char **argv) {
  const char *only = NULL;
  nb_t nb;
  memset(&nb, 0, sizeof nb);
  snprintf(nb.out, sizeof nb.out, "out/numerics");
  snprintf(nb.assets, sizeof nb.assets, "%s/assets", NUMERICS_SOURCE_DIR);
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--quick")) nb.quick = 1;
    else if (!strcmp(argv[i], "--out") && i + 1 < argc) snprintf(nb.out, sizeof nb.out, "%s", argv[++i]);
    else if (!strcmp(argv[i], "--assets") && i + 1 < argc) snprintf(nb.assets, sizeof nb.assets, "%s", argv[++i]);
    else if (!strcmp(argv[i], "--only") && i + 1 < argc) only = argv[++i];
    else {
      fprintf(stderr, "usage: bench_numerics [--quick] [--out DIR] [--assets DIR] "
                      "[--only spring,chain,cloth,stability,bar,ball,probe,incision,scaling]\n");
      return 2;
    }
  }
  if (mkdir_p(nb.out)) {
    fprintf(stderr, "bench_numerics: cannot create %s: %s\n", nb.out, strerror(errno));
    return 1;
  }
  char cpu[256];
  cpu_name(cpu, sizeof cpu);
  printf("bench_numerics%s: one core, double precision, %s build, flags '%s', %s\n", nb.quick ? " --quick" : "",
         NUMERICS_BUILD_TYPE, NUMERICS_C_FLAGS,
#ifdef __VERSION__
         "cc " __VERSION__
#else
         "cc ?"
#endif
  );
  printf("machine: %s; output: %s\n", cpu, nb.out);
  fflush(stdout);
  uint64_t t0 = vtime_mono_ns();

  if (wanted(only, "spring")) scene_spring(&nb);
  if (wanted(only, "chain")) scene_chain(&nb);
  if (wanted(only, "cloth")) scene_cloth(&nb);
  if (wanted(only, "stability")) scene_stability(&nb);
  if (wanted(only, "bar")) scene_bar(&nb);
  if (wanted(only, "ball")) scene_ball(&nb);
  if (wanted(only, "probe")) scene_probe(&nb);
  if (wanted(only, "incision")) scene_incision(&nb);
  if (wanted(only, "scaling")) scene_scaling(&nb);
  if (!only) {
    nb_skip(&nb, "plot 6 uses the S2 chain (1e6 steps); no energy plot for the bar or the organs");
  }

  FILE *csv = nb_csv(&nb, "summary.csv",
                     "scene,model,integrator,setting,dt,substeps,iterations,metric,err_max,err_end,step_us_median,"
                     "wall_ms_per_sim_s");
  if (csv) {
    for (size_t i = 0; i < nb.nrows; i++) {
      const nb_row_t *r = &nb.rows[i];
      fprintf(csv, "%s,%s,%s,%s,%.9g,%d,%d,%s,%.6e,%.6e,%.3f,%.4f\n", r->scene, r->model, r->integ, r->setting, r->dt,
              r->substeps, r->iterations, r->metric, r->err, r->err_end, r->step_us, r->sim_ms);
    }
    fclose(csv);
  }
  print_summary(&nb);
  printf(
      "\nerr: e_x = mass-weighted RMS position error / bounding-box diagonal against a converged run of the same "
      "model (S1: against the exact solution, over the amplitude; S8: probe force RMS error / peak force); "
      "us/step: median wall time of one scene step (sub-steps included); ms/sim-s: that median x steps per simulated "
      "second.\n");
  if (nb.ntargets) {
    printf("\ndocs/numerics.md §7 targets measured here:\n");
    for (int i = 0; i < nb.ntargets; i++) printf("  - %s\n", nb.targets[i]);
  }
  if (nb.nskipped) {
    printf("\nnot measured:\n");
    for (int i = 0; i < nb.nskipped; i++) printf("  - %s\n", nb.skipped[i]);
  }
  printf("\n%d plots and the CSV files are in %s (%.0f s)\n", nb.nplots, nb.out, (double)(vtime_mono_ns() - t0) * 1e-9);
  free(nb.rows);
  /* cairo/fontconfig caches, else the sanitizer build's leak check fails. */
  plot_cleanup();
  return 0;
}
