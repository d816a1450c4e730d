/* bench_server: server step time per generated organ and MeshDelta size.
 *
 * For each organ mesh in assets/meshes it builds the default material's
 * surface mass-spring scene with one probe, runs 500 free steps and 2000
 * steps with the probe pressed 8 mm into the organ's top, and reports the
 * step time (median, p99; one core, this build's flags), the cost of one
 * physics sub-step, and the MeshDelta payload per published frame (30 Hz)
 * against full float positions. Prints a table and writes CSV.
 * usage: bench_server ASSETS_DIR [OUT.csv] [--quick] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_publisher.h"
#include "scene_runtime.h"
#include "vstats.h"
#include "vtime.h"

static const char *ORGANS[] = {"tissue_block", "spleen", "kidney", "gallbladder", "liver_large"};

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: bench_server ASSETS_DIR [OUT.csv] [--quick]\n");
    return 2;
  }
  const char *csv_path = NULL;
  int quick = 0;
  for (int i = 2; i < argc; i++) {
    if (!strcmp(argv[i], "--quick")) quick = 1;
    else csv_path = argv[i];
  }
  int free_steps = quick ? 100 : 500, press_steps = quick ? 300 : 2000;
  FILE *csv = csv_path ? fopen(csv_path, "w") : NULL;
  if (csv_path && !csv) {
    fprintf(stderr, "bench_server: cannot write %s\n", csv_path);
    return 1;
  }
  if (csv)
    fprintf(csv, "organ,vertices,triangles,springs,substeps,stable_dt_ms,step_us_median,step_us_p99,substep_us,"
                 "contact_step_us_median,delta_bytes_mean,full_bytes,ratio\n");
  printf("%-13s %7s %7s %7s %4s %9s %11s %9s %10s %12s %11s %10s %7s\n", "organ", "verts", "tris", "springs", "sub",
         "stable_ms", "step_med_us", "p99_us", "substep_us", "contact_med", "delta_B", "full_B", "ratio");
  /* The quick setting (CI smoke) leaves out the 23k-vertex liver. */
  size_t norgans = sizeof ORGANS / sizeof ORGANS[0] - (quick ? 1 : 0);
  for (size_t oi = 0; oi < norgans; oi++) {
    char yaml[2048];
    snprintf(yaml, sizeof yaml,
             "scene: bench\norgans:\n  - name: %s\n    mesh: %s/meshes/%s.obj\n    material: {mass: 0.15}\n"
             "tools:\n  - name: probe\n    radius: 0.003\n    stiffness: 400\n",
             ORGANS[oi], argv[1], ORGANS[oi]);
    static scene_t sc;
    static runtime_t rt;
    verr_t err;
    if (scene_load_string(yaml, "bench", NULL, &sc, &err) || runtime_init(&rt, &sc, &err)) {
      fprintf(stderr, "bench_server: %s\n", err.msg);
      return 1;
    }
    organ_rt_t *o = &rt.organs[0];
    /* The probe comes down on the highest vertex. */
    size_t top = 0;
    for (size_t i = 0; i < o->ms.n; i++)
      if (o->ms.x[3 * i + 2] > o->ms.x[3 * top + 2]) top = i;
    double above[3] = {o->ms.x[3 * top], o->ms.x[3 * top + 1], o->ms.x[3 * top + 2] + 0.02};
    mesh_publisher_t mp;
    mesh_publisher_init(&mp, 0, o->rest.nverts, o->rest.tris, o->rest.ntris, (float)sc.quant_step, 0, 0, &err);
    mesh_publisher_keyframe(&mp, o->ms.x, 0);
    int total = free_steps + press_steps;
    double *t_free = malloc(sizeof(double) * (size_t)total), *t_press = malloc(sizeof(double) * (size_t)total);
    size_t nf = 0, np = 0;
    double delta_sum = 0;
    int frames = 0;
    for (int s = 0; s < total; s++) {
      double p[3] = {above[0], above[1], above[2]};
      if (s >= free_steps) { /* descend 28 mm in 200 steps, then hold (8 mm inside) */
        double a = fmin(1.0, (s - free_steps) / 200.0);
        p[2] = above[2] - a * 0.028;
      }
      runtime_set_tool(&rt, 0, p, 4);
      uint64_t t0 = vtime_mono_ns();
      runtime_step(&rt);
      double us = (double)(vtime_mono_ns() - t0) * 1e-3;
      if (s < free_steps) t_free[nf++] = us;
      else if (rt.tools[0].proxy.in_contact) t_press[np++] = us;
      if (s % 33 == 0 && s >= free_steps) {
        mesh_publisher_frame(&mp, o->ms.x, 0);
        delta_sum += (double)mesh_publisher_last_delta_bytes(&mp);
        frames++;
      }
    }
    vstats_summary_t f = vstats_summarise(t_free, nf), c = vstats_summarise(t_press, np);
    double full = 12.0 * (double)o->rest.nverts, dmean = frames ? delta_sum / frames : 0;
    printf("%-13s %7zu %7zu %7zu %4d %9.3f %11.1f %9.1f %10.1f %12.1f %11.0f %10.0f %7.3f\n", ORGANS[oi],
           o->rest.nverts, o->rest.ntris, o->ms.nsprings, o->substeps, o->stable_dt * 1e3, f.median, f.p99,
           f.median / o->substeps, c.median, dmean, full, dmean / full);
    if (csv)
      fprintf(csv, "%s,%zu,%zu,%zu,%d,%.4f,%.2f,%.2f,%.2f,%.2f,%.0f,%.0f,%.4f\n", ORGANS[oi], o->rest.nverts,
              o->rest.ntris, o->ms.nsprings, o->substeps, o->stable_dt * 1e3, f.median, f.p99, f.median / o->substeps,
              c.median, dmean, full, dmean / full);
    free(t_free);
    free(t_press);
    mesh_publisher_destroy(&mp);
    runtime_destroy(&rt);
  }
  if (csv) fclose(csv);
  return 0;
}
