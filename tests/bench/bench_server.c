/* SPDX-License-Identifier: Apache-2.0 */
/* bench_server: server step time per generated organ and integrator, and
 * MeshDelta size.
 *
 * For each organ mesh in assets/meshes and each integrator it builds the
 * default material's surface mass-spring scene with one probe (stiffness
 * 400 N/m), runs free steps and then steps with the probe pressed 8 mm into
 * the organ's top, and reports the sub-steps the model chose and its stable
 * dt, the step time (median, p99; one core, this build's flags), the cost of
 * one sub-step, the step time in contact and the MeshDelta payload per
 * published frame (30 Hz) against full float positions. Prints a table and
 * writes CSV. A configuration that would take long (explicit Euler needs
 * many sub-steps) runs fewer free steps; the press always runs in full.
 * usage: bench_server ASSETS_DIR [OUT.csv] [--quick] [--integrators a,b,...]
 *   default integrators: symplectic_euler,verlet,rk4,implicit_euler,explicit_euler
 *   --quick: symplectic_euler and implicit_euler, no 23k-vertex liver. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "runtime/scene_runtime.h"
#include "session/mesh_publisher.h"
#include "test_assets.h"
#include "test_runtime.h"
#include "vstats.h"
#include "vtime.h"

static const char *ORGANS[] = {"tissue_block", "spleen", "kidney", "gallbladder", "liver_large"};

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: bench_server ASSETS_DIR [OUT.csv] [--quick] [--integrators a,b,...]\n");
    return 2;
  }
  const char *csv_path = NULL;
  char integrators[256] = "symplectic_euler,verlet,rk4,implicit_euler,explicit_euler";
  int quick = 0, given = 0;
  for (int i = 2; i < argc; i++) {
    if (!strcmp(argv[i], "--quick"))
      quick = 1;
    else if (!strcmp(argv[i], "--integrators") && i + 1 < argc) {
      snprintf(integrators, sizeof integrators, "%s", argv[++i]);
      given = 1;
    } else
      csv_path = argv[i];
  }
  if (quick && !given) snprintf(integrators, sizeof integrators, "%s", "symplectic_euler,implicit_euler");
  int free_steps = quick ? 100 : 500, press_steps = quick ? 300 : 2000;
  double budget_s = quick ? 2 : 8; /* per configuration, for the free steps */
  FILE *csv = csv_path ? fopen(csv_path, "w") : NULL;
  if (csv_path && !csv) {
    fprintf(stderr, "bench_server: cannot write %s\n", csv_path);
    return 1;
  }
  if (csv)
    fprintf(csv, "organ,integrator,vertices,triangles,nodes,tets,substeps,stable_dt_ms,step_us_median,step_us_p99,"
                 "substep_us,contact_step_us_median,delta_bytes_mean,full_bytes,ratio\n");
  printf("%-13s %-16s %7s %7s %7s %4s %9s %11s %9s %10s %12s %9s %9s %7s\n", "organ", "integrator", "verts", "tris",
         "tets", "sub", "stable_ms", "step_med_us", "p99_us", "substep_us", "contact_med", "delta_B", "full_B",
         "ratio");
  /* The quick setting (CI smoke) leaves out the 23k-vertex liver. */
  size_t norgans = sizeof ORGANS / sizeof ORGANS[0] - (quick ? 1 : 0);
  test_assets_dir_set(argv[1]);
  for (size_t oi = 0; oi < norgans; oi++) {
    char list[256];
    snprintf(list, sizeof list, "%s", integrators);
    for (char *save = NULL, *integ = strtok_r(list, ",", &save); integ; integ = strtok_r(NULL, ",", &save)) {
      char mesh[64], organ_keys[256];
      snprintf(mesh, sizeof mesh, "%s.obj", ORGANS[oi]);
      snprintf(organ_keys, sizeof organ_keys, "    integrator: %s\n    material: {mass: 0.15}\n", integ);
      static scene_t sc;
      static runtime_t rt;
      verr_t err;
      if (!test_runtime_one_organ(NULL, &sc, "bench", mesh, organ_keys, "radius: 0.003, stiffness: 400", &err)) {
        fprintf(stderr, "bench_server: %s\n", err.msg);
        return 1;
      }
      if (runtime_init(&rt, &sc, &err)) { /* e.g. too many sub-steps: say so, go on */
        printf("%-13s %-16s refused: %s\n", ORGANS[oi], integ, err.msg);
        continue;
      }
      organ_rt_t *o = &rt.organs[0];
      const model_t *m = o->model;
      /* The probe comes down on the highest surface vertex. */
      size_t top = 0;
      for (size_t i = 0; i < m->nsurf; i++)
        if (m->surf_x[3 * i + 2] > m->surf_x[3 * top + 2]) top = i;
      double above[3] = {m->surf_x[3 * top], m->surf_x[3 * top + 1], m->surf_x[3 * top + 2] + 0.02};
      mesh_publisher_t mp;
      mesh_publisher_init(&mp, 0, m->nsurf, m->surf_tris, m->nsurf_tris, (float)sc.quant_step, 0, 0, &err);
      mesh_publisher_keyframe(&mp, m->surf_x, 0);
      /* Probe the cost with a few steps, then fit the free steps to the budget. */
      uint64_t t_probe = vtime_mono_ns();
      for (int s = 0; s < 5; s++) {
        runtime_set_tool(&rt, 0, above, 4);
        runtime_step(&rt);
      }
      double per_step = (double)(vtime_mono_ns() - t_probe) * 1e-9 / 5;
      int nfree = free_steps;
      if (per_step * nfree > budget_s) nfree = (int)fmax(20, budget_s / per_step);
      int total = nfree + press_steps;
      double *t_free = malloc(sizeof(double) * (size_t)total), *t_press = malloc(sizeof(double) * (size_t)total);
      size_t nf = 0, np = 0;
      double delta_sum = 0;
      int frames = 0;
      for (int s = 0; s < total; s++) {
        double p[3] = {above[0], above[1], above[2]};
        if (s >= nfree) { /* descend 28 mm in 200 steps, then hold (8 mm inside) */
          double a = fmin(1.0, (s - nfree) / 200.0);
          p[2] = above[2] - a * 0.028;
        }
        runtime_set_tool(&rt, 0, p, 4);
        uint64_t t0 = vtime_mono_ns();
        runtime_step(&rt);
        double us = (double)(vtime_mono_ns() - t0) * 1e-3;
        if (s < nfree)
          t_free[nf++] = us;
        else if (rt.tools[0].proxy.in_contact)
          t_press[np++] = us;
        if (s % 33 == 0 && s >= nfree) {
          mesh_publisher_frame(&mp, m->surf_x, 0);
          delta_sum += (double)mesh_publisher_last_delta_bytes(&mp);
          frames++;
        }
      }
      vstats_summary_t f = vstats_summarise(t_free, nf), c = vstats_summarise(t_press, np);
      double full = 12.0 * (double)m->nsurf, dmean = frames ? delta_sum / frames : 0;
      printf("%-13s %-16s %7zu %7zu %7zu %4d %9.3f %11.1f %9.1f %10.1f %12.1f %9.0f %9.0f %7.3f%s\n", ORGANS[oi], integ,
             m->nsurf, m->nsurf_tris, m->ntets, m->substeps, m->stable_dt * 1e3, f.median, f.p99,
             f.median / m->substeps, c.median, dmean, full, dmean / full,
             rt.organs[0].rollbacks ? "  (rollbacks!)" : "");
      if (csv)
        fprintf(csv, "%s,%s,%zu,%zu,%zu,%zu,%d,%.4f,%.2f,%.2f,%.2f,%.2f,%.0f,%.0f,%.4f\n", ORGANS[oi], integ, m->nsurf,
                m->nsurf_tris, m->nnodes, m->ntets, m->substeps, m->stable_dt * 1e3, f.median, f.p99,
                f.median / m->substeps, c.median, dmean, full, dmean / full);
      free(t_free);
      free(t_press);
      mesh_publisher_destroy(&mp);
      runtime_destroy(&rt);
    }
  }
  if (csv) fclose(csv);
  return 0;
}
