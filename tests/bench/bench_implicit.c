/* SPDX-License-Identifier: Apache-2.0 */
/* bench_implicit: CPU time per 1 ms step of the large-step integrator
 * implicit_pcg (issue 17.3) against the explicit live default
 * (symplectic_euler, its own sub-steps) on the same organ with the probe
 * pressing, in interleaved pairs.
 *
 * Per organ both runtimes are built from the same scene text (default
 * material, mass 0.15 kg, 400 N/m probe, as bench_server) and stepped in
 * turns, one step each: the probe starts 20 mm above the highest vertex,
 * descends 28 mm in 0.2 s and holds (8 mm below the rest surface). Steps
 * after the first 0.3 s of hold are timed with thread CPU time
 * (vtime_thread_cpu_ns), so the two schemes see the same machine load.
 * Printed per organ and scheme: sub-steps, CPU per step (median, p95),
 * mean CG iterations, the held force, and the differences of the held force
 * and of the surface (RMS over vertices, relative to the dent) from the
 * explicit run. Figures are not asserted.
 * usage: bench_implicit ASSETS_DIR [--quick] [--hold S] [--cap N] [--organs a,b]
 *   --quick: kidney only, 0.2 s of timed hold (ctest smoke) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "physics/model_mass_spring.h"
#include "runtime/scene_runtime.h"
#include "test_assets.h"
#include "test_runtime.h"
#include "vstats.h"
#include "vtime.h"

#define NSCHEMES 2

typedef struct run {
  scene_t sc;
  runtime_t rt;
  double *us;
  size_t nus;
  double cg_sum, cg_n;
} run_t;

static const model_t *model_of(const run_t *r) { return r->rt.organs[0].model; }

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: bench_implicit ASSETS_DIR [--quick] [--hold S] [--cap N] [--organs a,b]\n");
    return 2;
  }
  int quick = 0, cap = 0;
  double hold = 1.0;
  char organs[256] = "kidney,gallbladder,liver_large";
  for (int i = 2; i < argc; i++) {
    if (!strcmp(argv[i], "--quick"))
      quick = 1;
    else if (!strcmp(argv[i], "--hold") && i + 1 < argc)
      hold = atof(argv[++i]);
    else if (!strcmp(argv[i], "--cap") && i + 1 < argc)
      cap = atoi(argv[++i]);
    else if (!strcmp(argv[i], "--organs") && i + 1 < argc)
      snprintf(organs, sizeof organs, "%s", argv[++i]);
  }
  if (quick) {
    snprintf(organs, sizeof organs, "kidney");
    hold = 0.2;
  }
  test_assets_dir_set(argv[1]);
  static const char *const SCHEMES[NSCHEMES] = {"symplectic_euler", "implicit_pcg"};
  printf("%-12s %-17s %4s %9s %9s %7s %9s %10s %10s\n", "organ", "integrator", "sub", "cpu_med_us", "cpu_p95_us",
         "cg_it", "force_N", "dF_rel", "dx_rel");
  char list[256];
  snprintf(list, sizeof list, "%s", organs);
  for (char *save = NULL, *organ = strtok_r(list, ",", &save); organ; organ = strtok_r(NULL, ",", &save)) {
    run_t *runs = calloc(NSCHEMES, sizeof *runs);
    if (!runs) return 1;
    char mesh[64];
    snprintf(mesh, sizeof mesh, "%s.obj", organ);
    int ok = 1;
    for (int k = 0; k < NSCHEMES && ok; k++) {
      char keys[256];
      int c = k == 1 && cap > 0 ? cap : 0;
      if (c)
        snprintf(keys, sizeof keys,
                 "    integrator: %s\n    material: {mass: 0.15}\n    solver: {cg_max_iterations: %d}\n", SCHEMES[k],
                 c);
      else
        snprintf(keys, sizeof keys, "    integrator: %s\n    material: {mass: 0.15}\n", SCHEMES[k]);
      verr_t err;
      if (!test_runtime_one_organ(NULL, &runs[k].sc, "bench", mesh, keys, "radius: 0.003, stiffness: 400", &err) ||
          runtime_init(&runs[k].rt, &runs[k].sc, &err)) {
        fprintf(stderr, "bench_implicit: %s: %s\n", organ, err.msg);
        ok = 0;
      }
    }
    if (!ok) return 1;
    const model_t *m0 = model_of(&runs[0]);
    size_t top = 0;
    for (size_t i = 0; i < m0->nsurf; i++)
      if (m0->surf_rest[3 * i + 2] > m0->surf_rest[3 * top + 2]) top = i;
    double above[3] = {m0->surf_rest[3 * top], m0->surf_rest[3 * top + 1], m0->surf_rest[3 * top + 2] + 0.02};
    long descend = 200, settle = 300, timed = lround(hold * 1000);
    for (int k = 0; k < NSCHEMES; k++) runs[k].us = malloc((size_t)timed * sizeof(double));
    for (long s = 0; s < descend + settle + timed; s++) {
      double p[3] = {above[0], above[1], above[2] - 0.028 * fmin(1.0, (double)s / (double)descend)};
      for (int k = 0; k < NSCHEMES; k++) {
        run_t *r = &runs[(s + k) % NSCHEMES]; /* alternate which goes first */
        runtime_set_tool(&r->rt, 0, p, 4);
        uint64_t t0 = vtime_thread_cpu_ns();
        runtime_step(&r->rt);
        uint64_t t1 = vtime_thread_cpu_ns();
        if (s >= descend + settle) r->us[r->nus++] = (double)(t1 - t0) * 1e-3;
      }
      if (s == descend + settle - 1 || s == descend + settle + timed - 1)
        for (int k = 0; k < NSCHEMES; k++) { /* CG iterations over the timed steps */
          uint64_t it, st;
          if (model_mass_spring_cg_counts(runs[k].rt.organs[0].model, &it, &st)) continue;
          double sign = s == descend + settle - 1 ? -1 : 1;
          runs[k].cg_sum += sign * (double)it;
          runs[k].cg_n += sign * (double)st;
        }
    }
    const model_t *me = model_of(&runs[0]);
    double fe = sqrt(runs[0].rt.tools[0].force[0] * runs[0].rt.tools[0].force[0] +
                     runs[0].rt.tools[0].force[1] * runs[0].rt.tools[0].force[1] +
                     runs[0].rt.tools[0].force[2] * runs[0].rt.tools[0].force[2]);
    double dent = fabs(me->surf_x[3 * top + 2] - me->surf_rest[3 * top + 2]);
    for (int k = 0; k < NSCHEMES; k++) {
      const model_t *m = model_of(&runs[k]);
      const double *f = runs[k].rt.tools[0].force;
      double fk = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]), dx = 0;
      for (size_t c = 0; c < 3 * m->nsurf; c++) dx += (m->surf_x[c] - me->surf_x[c]) * (m->surf_x[c] - me->surf_x[c]);
      dx = sqrt(dx / (double)m->nsurf);
      vstats_summary_t st = vstats_summarise(runs[k].us, runs[k].nus);
      printf("%-12s %-17s %4d %9.1f %9.1f %7.2f %9.4f %10.2e %10.2e%s\n", organ, SCHEMES[k], m->substeps, st.median,
             st.p95, runs[k].cg_n > 0 ? runs[k].cg_sum / runs[k].cg_n : 0.0, fk, fabs(fk - fe) / fe,
             dent > 0 ? dx / dent : 0.0, runs[k].rt.organs[0].rollbacks ? "  (rollbacks!)" : "");
    }
    for (int k = 0; k < NSCHEMES; k++) {
      free(runs[k].us);
      runtime_destroy(&runs[k].rt);
    }
    free(runs);
  }
  return 0;
}
