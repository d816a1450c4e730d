/* SPDX-License-Identifier: Apache-2.0 */
/* bench_models: CPU time per 1 ms step of every model on every shipped
 * organ mesh, with the probe pressing, and the slope of cost against
 * vertex count per model (issue 17 item 4, docs/numerics.md §9).
 *
 * For each model (mass_spring_surface under symplectic Euler, the live
 * default; mass_spring_tet; molecular with the kidney_molecular.yaml
 * material under implicit_pcg, its scene's integrator, and under Verlet and
 * symplectic Euler; pbd; xpbd; vertex_based; adaptive_mass_spring with the
 * kidney_adaptive.yaml material, refined under the probe), each at the scene
 * defaults (every key the scene leaves out: sub-steps chosen by the model,
 * solver iterations, automatic tetrahedron size) with the default material
 * (0.15 kg), and each organ of assets/meshes (tissue_block, spleen, kidney,
 * gallbladder, liver_large; --quick: the first three), through the
 * product's runtime: one probe (400 N/m, 4 N) comes down over the organ's
 * highest vertex at 5 cm/s until it holds 1 N (or 8 mm down), is held
 * 0.2 s, then `steps` steps are timed one by one, by the thread's CPU time
 * (a loaded machine inflates it less than wall time) and by wall time.
 * XPBD and molecular rows also carry their S8-style accuracy on that organ:
 * the RMS force error of the same press (0.3 s: down, then held) against
 * the model's reference at 1/4 ms (XPBD: 4 sub-steps, its reference setting
 * in S8; molecular: Verlet with 4 sub-steps), relative to the peak reference
 * force (--quick leaves it out). The mass_spring_surface row's figure is
 * that of its regional sleeping (physics/ms_regions.h, on by default): the
 * same press against the same model with it off (solver.region_force 0)
 * at the same 1 ms step; mass_spring_awake is that model's cost.
 * Prints one row per case, then per model the fitted log-log slope of CPU
 * time against simulated nodes (the surface vertices of surface models, the
 * tetrahedral mesh's nodes of volume models; plot_loglog_slope), writes the plot as
 * PNG when OUT.png is given. Figures are never asserted; the machine's load
 * average is printed with them.
 * usage: bench_models [--quick] [--model NAME] [--organ NAME] [--xpbd-iterations N] [OUT.png]
 *   (--model, --organ: that model, that organ only; --xpbd-iterations: XPBD
 *   at N iterations, the reference still at 10) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "physics/model_mass_spring.h"
#include "plot/plot.h"
#include "runtime/scene_runtime.h"
#include "test_runtime.h"
#include "vmath.h"
#include "vstats.h"
#include "vtime.h"

static const char *ORGANS[] = {"tissue_block", "spleen", "kidney", "gallbladder", "liver_large"};
#define NORGANS 5

typedef struct model_case {
  const char *label, *keys;
  const char *ref; /* S8-style reference setting (run at 1/4 ms), NULL: no accuracy column */
} model_case_t;

/* A reference that turns regional sleeping off (ms_regions.h) judges that
 * mechanism alone: it runs at the same 1 ms step. */
static int ref_same_dt(const model_case_t *mc) { return mc->ref && strstr(mc->ref, "region_force: 0") != NULL; }

#define MOL_MATERIAL                                                                                                   \
  "    material: {mass: 0.15, bond_k: 30, angle_k: 3.0e-5, stretch_bend_k: 0, home_stiffness: 30, home_damping: "      \
  "0.005}\n"
/* Molecular reference: Verlet at 1/4 ms with 4 sub-steps (1/16 ms, 2.5-5x
 * inside its stability bound on the shipped organs). */
#define MOL_REF "    model: molecular\n    integrator: verlet\n    solver: {substeps: 4}\n" MOL_MATERIAL

static model_case_t MODELS[] = {
    {"mass_spring_surface",
     "    model: mass_spring_surface\n    integrator: symplectic_euler\n"
     "    material: {mass: 0.15}\n",
     "    model: mass_spring_surface\n    integrator: symplectic_euler\n"
     "    material: {mass: 0.15}\n    solver: {region_force: 0}\n"},
    {"mass_spring_awake",
     "    model: mass_spring_surface\n    integrator: symplectic_euler\n"
     "    material: {mass: 0.15}\n    solver: {region_force: 0}\n",
     NULL},
    {"mass_spring_tet", "    model: mass_spring_tet\n    integrator: symplectic_euler\n    material: {mass: 0.15}\n",
     NULL},
    {"molecular", "    model: molecular\n    integrator: implicit_pcg\n" MOL_MATERIAL, MOL_REF},
    {"molecular_verlet", "    model: molecular\n    integrator: verlet\n" MOL_MATERIAL, MOL_REF},
    {"molecular_symplectic", "    model: molecular\n    integrator: symplectic_euler\n" MOL_MATERIAL, MOL_REF},
    {"pbd", "    model: pbd\n    material: {mass: 0.15}\n", NULL},
    {"xpbd", "    model: xpbd\n    material: {mass: 0.15}\n",
     "    model: xpbd\n    material: {mass: 0.15}\n    solver: {substeps: 4, iterations: 10}\n"},
    {"vertex_based", "    model: vertex_based\n    material: {mass: 0.15}\n", NULL},
    /* assets/scenes/kidney_adaptive.yaml's material: refines under the probe. */
    {"adaptive_mass_spring",
     "    model: adaptive_mass_spring\n    integrator: symplectic_euler\n"
     "    material: {mass: 0.15, stiffness: 30, damping: 0.02, home_stiffness: 30, home_damping: 0.005, "
     "refine_area: 1.0e-6, refine_levels: 2}\n",
     NULL},
};
#define NMODELS (sizeof MODELS / sizeof MODELS[0])

static double load_average(void) {
  double l = NAN;
  FILE *f = fopen("/proc/loadavg", "r");
  if (f) {
    if (fscanf(f, "%lf", &l) != 1) l = NAN;
    fclose(f);
  }
  return l;
}

typedef struct result {
  int ok, substeps;
  size_t verts, nodes, tets;
  double cpu_us, wall_us, force, s8; /* medians per step; force held (N); XPBD accuracy (relative RMS) */
  double awake_frac;                 /* regional sleeping: node updates / (nodes x sub-steps) while timed, or -1 */
} result_t;

/* Press and hold in the loaded runtime; the device path is the same for
 * every run of an organ (so a reference run sees the same commands).
 * Writes the force at every step of the press into force[] when given. */
static void press(runtime_t *rt, const double top[3], int hold, double *force, int nforce, double p[3]) {
  v3_copy(p, top);
  p[2] += 0.002;
  int s = 0;
  for (; s < 200 && v3_norm(rt->tools[0].force) < 1.0; s++) {
    p[2] -= 5e-5;
    runtime_set_tool(rt, 0, p, 100);
    runtime_step(rt);
    if (force && s < nforce) force[s] = v3_norm(rt->tools[0].force);
  }
  for (int h = 0; h < hold; h++, s++) {
    runtime_set_tool(rt, 0, p, 100);
    runtime_step(rt);
    if (force && s < nforce) force[s] = v3_norm(rt->tools[0].force);
  }
}

static int load(runtime_t *rt, scene_t *sc, const char *organ, const char *keys, const char *physics, double top[3]) {
  char mesh[64], yaml[2048];
  snprintf(mesh, sizeof mesh, "%s.obj", organ);
  snprintf(yaml, sizeof yaml,
           "scene: models\nphysics: {%s, publish_hz: 30}\norgans:\n  - name: organ\n    mesh: ../meshes/%s\n%s"
           "tools:\n  - {name: probe, kind: probe, radius: 0.003, stiffness: 400, max_force: 4}\n",
           physics, mesh, keys);
  verr_t err;
  if (!test_runtime_load(rt, sc, yaml, &err)) return -1;
  const model_t *m = rt->organs[0].model;
  size_t t = 0;
  for (size_t i = 1; i < m->nsurf; i++)
    if (m->surf_rest[3 * i + 2] > m->surf_rest[3 * t + 2]) t = i;
  v3_copy(top, m->surf_rest + 3 * t);
  return 0;
}

/* The S8-style error on this organ (see the file comment). */
static double s8_accuracy(const char *organ, const char *keys, const char *ref_keys, int same_dt) {
  static scene_t sc;
  static runtime_t rt;
  enum { N = 300, R = 4 }; /* 0.3 s of 1 ms steps; the reference steps 1/4 ms */
  const int r = same_dt ? 1 : R;
  double f[N], fr[R * N], top[3];
  for (int i = 0; i < N; i++) f[i] = NAN;
  for (int i = 0; i < R * N; i++) fr[i] = NAN;
  if (load(&rt, &sc, organ, keys, "dt: 0.001", top)) return NAN;
  double pe[3];
  press(&rt, top, N, f, N, pe);
  runtime_destroy(&rt);
  /* The reference takes 4 steps per 1 ms command (the device moves by the
   * same amount per 1 ms, so the press runs at the same speed). */
  if (load(&rt, &sc, organ, ref_keys, same_dt ? "dt: 0.001" : "dt: 0.00025", top)) return NAN;
  double p[3];
  v3_copy(p, top);
  p[2] += 0.002;
  int s = 0, pressing = 1;
  for (; s < N; s++) {
    if (pressing && s < 200) p[2] -= 5e-5;
    for (int k = 0; k < r; k++) {
      runtime_set_tool(&rt, 0, p, 100);
      runtime_step(&rt);
    }
    fr[s] = v3_norm(rt.tools[0].force);
    if (fr[s] >= 1.0) pressing = 0;
  }
  runtime_destroy(&rt);
  double e2 = 0, peak = 0;
  int n = 0;
  for (int i = 0; i < N; i++)
    if (isfinite(f[i]) && isfinite(fr[i])) {
      e2 += (f[i] - fr[i]) * (f[i] - fr[i]);
      peak = fmax(peak, fr[i]);
      n++;
    }
  return n && peak > 0 ? sqrt(e2 / n) / peak : NAN;
}

static result_t run_case(const char *organ, const model_case_t *mc, int steps, int quick) {
  static scene_t sc;
  static runtime_t rt;
  result_t r = {0};
  r.cpu_us = r.wall_us = r.force = r.s8 = NAN;
  double top[3];
  if (load(&rt, &sc, organ, mc->keys, "dt: 0.001", top)) return r;
  const model_t *m = rt.organs[0].model;
  double p[3];
  press(&rt, top, 200, NULL, 0, p);
  double *c = malloc(2 * (size_t)steps * sizeof *c), *w = c ? c + steps : NULL;
  if (!c) {
    runtime_destroy(&rt);
    return r;
  }
  ms_region_counts_t rc0, rc1;
  int regions = model_mass_spring_region_counts(m, &rc0) == 0;
  for (int s = 0; s < steps; s++) {
    uint64_t t0 = vtime_mono_ns(), c0 = vtime_thread_cpu_ns();
    runtime_set_tool(&rt, 0, p, 100);
    runtime_step(&rt);
    c[s] = (double)(vtime_thread_cpu_ns() - c0) * 1e-3;
    w[s] = (double)(vtime_mono_ns() - t0) * 1e-3;
  }
  r.ok = 1;
  r.awake_frac = -1;
  if (regions && model_mass_spring_region_counts(m, &rc1) == 0 && rc1.substeps > rc0.substeps)
    r.awake_frac = (double)(rc1.node_updates - rc0.node_updates) / ((double)(rc1.substeps - rc0.substeps) * rc1.nodes);
  r.cpu_us = vstats_summarise(c, (size_t)steps).median;
  r.wall_us = vstats_summarise(w, (size_t)steps).median;
  r.force = v3_norm(rt.tools[0].force);
  r.substeps = m->substeps;
  r.verts = m->nsurf;
  r.nodes = m->nnodes;
  r.tets = m->ntets;
  free(c);
  runtime_destroy(&rt);
  /* The XPBD reference is pinned at 10 iterations (the S8 setting), so runs
   * at other iteration counts are judged against the same curve. */
  if (!quick && mc->ref) r.s8 = s8_accuracy(organ, mc->keys, mc->ref, ref_same_dt(mc));
  return r;
}

int main(int argc, char **argv) {
  int quick = 0;
  const char *png = NULL, *only = NULL, *organ = NULL;
  static char xpbd_keys[160];
  model_case_t *xpbd_case = NULL;
  for (size_t mi = 0; mi < NMODELS; mi++)
    if (!strcmp(MODELS[mi].label, "xpbd")) xpbd_case = &MODELS[mi];
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--quick"))
      quick = 1;
    else if (!strcmp(argv[i], "--model") && i + 1 < argc)
      only = argv[++i];
    else if (!strcmp(argv[i], "--xpbd-iterations") && i + 1 < argc) {
      /* XPBD rows at this iteration count instead of the scene default. */
      snprintf(xpbd_keys, sizeof xpbd_keys,
               "    model: xpbd\n    material: {mass: 0.15}\n    solver: {iterations: %d}\n", atoi(argv[++i]));
      if (xpbd_case) xpbd_case->keys = xpbd_keys;
    } else if (!strcmp(argv[i], "--organ") && i + 1 < argc)
      organ = argv[++i];
    else
      png = argv[i];
  }
  int norgans = quick ? 3 : NORGANS, steps = quick ? 50 : 500;
  printf("bench_models: CPU and wall us per 1 ms step (medians of %d), probe holding about 1 N, scene defaults\n",
         steps);
  printf("%-20s %-13s %6s %6s %6s %4s %9s %9s %7s %8s %5s\n", "model", "organ", "verts", "nodes", "tets", "sub",
         "cpu_us", "wall_us", "force_N", "s8_rms", "load");
  plot_t pl;
  plot_init(&pl, "Step cost against size: every model, probe pressing, scene defaults",
            "simulated nodes (surface vertices of surface models)", "CPU time per 1 ms step (us)", 1, 1);
  for (size_t mi = 0; mi < NMODELS; mi++) {
    if (only && strcmp(only, MODELS[mi].label)) continue;
    double xs[NORGANS], ys[NORGANS], ysub[NORGANS];
    size_t n = 0;
    for (int oi = 0; oi < norgans; oi++) {
      if (organ && strcmp(organ, ORGANS[oi])) continue;
      result_t r = run_case(ORGANS[oi], &MODELS[mi], steps, quick);
      if (!r.ok) {
        printf("%-20s %-13s refused or failed\n", MODELS[mi].label, ORGANS[oi]);
        continue;
      }
      printf(r.s8 < 1e-3 ? "%-20s %-13s %6zu %6zu %6zu %4d %9.1f %9.1f %7.3f %8.1e %5.2f"
                         : "%-20s %-13s %6zu %6zu %6zu %4d %9.1f %9.1f %7.3f %8.4f %5.2f",
             MODELS[mi].label, ORGANS[oi], r.verts, r.nodes, r.tets, r.substeps, r.cpu_us, r.wall_us, r.force, r.s8,
             load_average());
      if (r.awake_frac >= 0) printf("  (timed steps: %.1f %% of the nodes integrated)", 100 * r.awake_frac);
      printf("\n");
      fflush(stdout);
      /* In order of nodes (the volume models' automatic tetrahedron size
       * does not grow with the surface), so the plotted line is a curve. */
      size_t at = n;
      while (at > 0 && xs[at - 1] > (double)r.nodes) {
        xs[at] = xs[at - 1];
        ys[at] = ys[at - 1];
        ysub[at] = ysub[at - 1];
        at--;
      }
      xs[at] = (double)r.nodes;
      ys[at] = r.cpu_us;
      ysub[at] = r.cpu_us / (r.substeps > 0 ? r.substeps : 1);
      n++;
    }
    size_t used = 0;
    double slope = plot_loglog_slope(n, xs, ys, 0, INFINITY, &used);
    /* Above the smallest meshes, where fixed per-step costs dominate. */
    size_t used_big = 0;
    double xb[NORGANS], yb[NORGANS];
    size_t nb = 0;
    for (size_t k = 0; k < n; k++)
      if (xs[k] >= 500) {
        xb[nb] = xs[k];
        yb[nb++] = ys[k];
      }
    double slope_big = plot_loglog_slope(nb, xb, yb, 0, INFINITY, &used_big);
    double slope_sub = plot_loglog_slope(n, xs, ysub, 0, INFINITY, NULL);
    printf("%-20s slope of log CPU time against log nodes: %.2f over %zu organs, %.2f over the %zu with >= 500; "
           "per sub-step %.2f\n",
           MODELS[mi].label, slope, used, slope_big, used_big, slope_sub);
    char lab[112];
    snprintf(lab, sizeof lab, "%s: %.2f (%.2f)", MODELS[mi].label, slope, slope_sub);
    plot_add(&pl, lab, n, xs, ys, (int)mi, (int)mi, PLOT_LINE_SOLID);
  }
  double ref[2] = {45, 23522}, refy[2] = {1000, 1000};
  plot_add(&pl, "real time (1 ms)", 2, ref, refy, PLOT_GREY, -1, PLOT_LINE_DASHED);
  plot_note(&pl, "after each model: log-log slope of the step (of one sub-step)");
  plot_note(&pl, "load average %.1f when written (2 cores shared)", load_average());
  int rc = 0;
  if (png) {
    verr_t err;
    if (plot_write_png(&pl, png, &err)) {
      fprintf(stderr, "bench_models: %s\n", err.msg);
      rc = 1;
    } else
      printf("wrote %s\n", png);
  }
  plot_free(&pl);
  return rc;
}
