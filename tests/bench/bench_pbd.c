/* SPDX-License-Identifier: Apache-2.0 */
/* bench_pbd: step time of the PBD / XPBD solver (docs/numerics.md §7 targets).
 *
 *   bar     the BarDemo bar of the PositionBasedDynamics library: 30x5x5
 *           nodes (750 nodes, 2,320 tetrahedra, 3,565 distance + 2,320
 *           volume constraints), the x = 0 face fixed, gravity, dt 5 ms,
 *           5 sub-steps x 1 iteration, XPBD (and PBD for comparison).
 *           Target <= 0.6 ms; the library takes 1.22 ms on these machines.
 *   spleen  the "xpbd" scene model on assets/meshes/spleen.obj (tetrahedra
 *           of 7 mm: about the seed's 711 nodes / 2,385 tetrahedra), scene
 *           defaults, dt 1 ms, 1 sub-step x 10 iterations, pressed by a 1 Hz
 *           0.5 N force on its top vertex. Target <= 0.5 ms. Also at the
 *           automatic tetrahedron size (cost against size).
 *
 * Per case: median and p95 step time over the run (one core, this build's
 * flags, double), cost per constraint projection, and the accuracy figures
 * at the end (max/RMS strain, global and worst |V/V0 - 1|, min V/V0).
 * Prints a table, optionally writes CSV.
 * usage: bench_pbd ASSETS_DIR [--csv OUT.csv] [--quick] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_import.h"
#include "physics/pbd.h"
#include "tet_mesh.h"
#include "vstats.h"
#include "vtime.h"

typedef struct row {
  const char *name;
  size_t nodes, tets, edges;
  int substeps, iterations;
  double dt, target_us;
  vstats_summary_t t; /* us */
  pbd_errors_t e;
  double extra; /* bar: tip sag (m); spleen: largest surface displacement (m) */
  uint64_t rollbacks;
} row_t;

static void print_row(const row_t *r, FILE *csv) {
  double projections = (double)(r->edges + r->tets) * r->substeps * r->iterations;
  printf("%-16s %6zu %6zu %6zu %3dx%-3d %5.1f %9.1f %9.1f %7.0f %8.2f %9.2e %9.2e %9.2e %7.3f %9.3g %3llu\n", r->name,
         r->nodes, r->tets, r->edges, r->substeps, r->iterations, 1e3 * r->dt, r->t.median, r->t.p95, r->target_us,
         1e3 * r->t.median / projections, r->e.strain_max, r->e.volume_global, r->e.volume_worst, r->e.min_volume_ratio,
         r->extra, (unsigned long long)r->rollbacks);
  if (csv)
    fprintf(csv, "%s,%zu,%zu,%zu,%d,%d,%g,%.3f,%.3f,%.3f,%.4f,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%llu\n", r->name, r->nodes,
            r->tets, r->edges, r->substeps, r->iterations, r->dt, r->t.median, r->t.p95, r->target_us,
            1e3 * r->t.median / projections, r->e.strain_max, r->e.strain_rms, r->e.volume_global, r->e.volume_worst,
            r->e.min_volume_ratio, r->extra, (unsigned long long)r->rollbacks);
}

/* The bar at BarDemo's scale: node spacing 0.3 m (8.7 m long), 1 kg per
 * node; XPBD compliance 1e-6 m/N per edge and 1e-8 per volume (the tip
 * settles about 0.6 m down, 2 % strain, no inverted tetrahedra; rigid
 * constraints at this 5 x 1 setting still sag 0.35 m: Gauss-Seidel does not
 * converge along the bar), PBD stiffness 1, damping 16 /s. */
static int bench_bar(row_t *r, pbd_mode_t mode, int steps) {
  tet_mesh_t tm;
  verr_t err;
  if (tet_mesh_box_grid(30, 5, 5, 0.3, &tm, &err)) {
    fprintf(stderr, "bench_pbd: %s\n", err.msg);
    return -1;
  }
  pbd_params_t p = {.mode = mode,
                    .mass = 750,
                    .distance_stiffness = 1,
                    .volume_stiffness = 1,
                    .distance_compliance = 1e-6,
                    .volume_compliance = 1e-8,
                    .gravity = {0, 0, -9.81},
                    .substeps = 5,
                    .iterations = 1,
                    .stiffness_correction = 1};
  pbd_t s;
  int rc = pbd_create(&s, tm.nnodes, tm.x, tm.ntets, tm.tets, &p, &err);
  tet_mesh_free(&tm);
  if (rc) {
    fprintf(stderr, "bench_pbd: %s\n", err.msg);
    return -1;
  }
  s.p.damping = 16 * s.mass[0];
  for (size_t i = 0; i < s.n; i++)
    if (s.x_rest[3 * i] < 1e-9) pbd_fix_node(&s, i);
  double *t = malloc((size_t)steps * sizeof *t);
  for (int k = 0; k < steps; k++) {
    uint64_t t0 = vtime_mono_ns();
    pbd_step(&s, 0.005, NULL, NULL);
    t[k] = (double)(vtime_mono_ns() - t0) * 1e-3;
  }
  *r = (row_t){.name = mode == PBD_MODE_XPBD ? "bar_xpbd" : "bar_pbd",
               .nodes = s.n,
               .tets = s.ntets,
               .edges = s.nedges,
               .substeps = 5,
               .iterations = 1,
               .dt = 0.005,
               .target_us = 600,
               .t = vstats_summarise(t, (size_t)steps),
               .rollbacks = s.rollbacks};
  pbd_errors(&s, &r->e);
  for (size_t i = 0; i < s.n; i++)
    if (s.x_rest[3 * i] > 28.5 * 0.3) r->extra += (s.x_rest[3 * i + 2] - s.x[3 * i + 2]) / 25;
  free(t);
  pbd_destroy(&s);
  return 0;
}

typedef struct press {
  uint32_t vertex;
  double t, amplitude;
} press_t;

/* A 1 Hz push on one surface vertex, applied every sub-step through the
 * model's contact hook as a tool would. */
static void press_hook(model_t *m, void *ctx) {
  press_t *p = ctx;
  double f[3] = {0, 0, -p->amplitude * 0.5 * (1 - cos(2 * M_PI * p->t))};
  m->ops->add_surface_force(m, p->vertex, f);
}

static int bench_spleen(row_t *r, const char *name, const mesh_t *surf, double tet_size, int steps) {
  scene_organ_t cfg;
  memset(&cfg, 0, sizeof cfg);
  snprintf(cfg.name, sizeof cfg.name, "spleen");
  snprintf(cfg.model, sizeof cfg.model, "xpbd");
  /* The scene defaults (common/scene.h). */
  cfg.material = (scene_material_t){.mass = 0.1,
                                    .home_stiffness = 30,
                                    .home_damping = 0.005,
                                    .distance_stiffness = 1,
                                    .volume_stiffness = 1,
                                    .distance_compliance = 1e-4,
                                    .volume_compliance = 1e-6};
  cfg.solver = (scene_solver_t){.substeps = 1, .iterations = 10, .tet_size = tet_size};
  model_params_t mp = {.cfg = &cfg, .surface = surf, .dt = 0.001, .tool_stiffness = 300};
  verr_t err;
  uint64_t b0 = vtime_mono_ns();
  model_t *m = model_pbd_create(&mp, &err);
  double build_ms = (double)(vtime_mono_ns() - b0) * 1e-6;
  if (!m) {
    fprintf(stderr, "bench_pbd: spleen: %s\n", err.msg);
    return -1;
  }
  press_t press = {0, 0, 0.5};
  for (size_t i = 0; i < m->nsurf; i++)
    if (m->surf_rest[3 * i + 2] > m->surf_rest[3 * press.vertex + 2]) press.vertex = (uint32_t)i;
  m->hook = press_hook;
  m->hook_ctx = &press;
  double *t = malloc((size_t)steps * sizeof *t), moved = 0;
  for (int k = 0; k < steps; k++) {
    press.t = k * 0.001;
    uint64_t t0 = vtime_mono_ns();
    m->ops->step(m, 0.001);
    t[k] = (double)(vtime_mono_ns() - t0) * 1e-3;
    for (size_t i = 0; i < m->nsurf; i++) {
      double d[3] = {m->surf_x[3 * i] - m->surf_rest[3 * i], m->surf_x[3 * i + 1] - m->surf_rest[3 * i + 1],
                     m->surf_x[3 * i + 2] - m->surf_rest[3 * i + 2]};
      moved = fmax(moved, sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
    }
  }
  const pbd_t *s = model_pbd_solver(m);
  *r = (row_t){.name = name,
               .nodes = m->nnodes,
               .tets = m->ntets,
               .edges = s->nedges,
               .substeps = m->substeps,
               .iterations = 10,
               .dt = 0.001,
               .target_us = 500,
               .t = vstats_summarise(t, (size_t)steps),
               .extra = moved,
               .rollbacks = m->rollbacks};
  pbd_errors(s, &r->e);
  printf("  (%s: %zu surface vertices, model built in %.1f ms)\n", name, m->nsurf, build_ms);
  free(t);
  model_destroy(m);
  return 0;
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: bench_pbd ASSETS_DIR [--csv OUT.csv] [--quick]\n");
    return 2;
  }
  const char *csv_path = NULL;
  int quick = 0;
  for (int i = 2; i < argc; i++) {
    if (!strcmp(argv[i], "--quick"))
      quick = 1;
    else if (!strcmp(argv[i], "--csv") && i + 1 < argc)
      csv_path = argv[++i];
    else {
      fprintf(stderr, "bench_pbd: unknown argument '%s'\n", argv[i]);
      return 2;
    }
  }
  FILE *csv = csv_path ? fopen(csv_path, "w") : NULL;
  if (csv_path && !csv) {
    fprintf(stderr, "bench_pbd: cannot write %s\n", csv_path);
    return 1;
  }
  if (csv)
    fprintf(csv,
            "case,nodes,tets,edges,substeps,iterations,dt_s,step_us_median,step_us_p95,target_us,"
            "ns_per_projection,strain_max,strain_rms,volume_error,volume_worst,min_volume_ratio,extra,rollbacks\n");
  int steps = quick ? 200 : 1000;
  char path[2048];
  snprintf(path, sizeof path, "%s/meshes/spleen.obj", argv[1]);
  mesh_t spleen;
  verr_t err;
  if (mesh_import(path, &spleen, &err)) {
    fprintf(stderr, "bench_pbd: %s\n", err.msg);
    if (csv) fclose(csv);
    return 1;
  }
  row_t rows[4];
  int nrows = 0, fail = 0;
  fail |= bench_bar(&rows[nrows++], PBD_MODE_XPBD, steps);
  fail |= bench_bar(&rows[nrows++], PBD_MODE_PBD, steps);
  fail |= bench_spleen(&rows[nrows++], "spleen_xpbd_7mm", &spleen, 0.007, steps);
  if (!quick) fail |= bench_spleen(&rows[nrows++], "spleen_xpbd_auto", &spleen, 0, steps);
  printf("\n%-16s %6s %6s %6s %-7s %5s %9s %9s %7s %8s %9s %9s %9s %7s %9s %3s\n", "case", "nodes", "tets", "edges",
         "sub x it", "dt_ms", "med_us", "p95_us", "target", "ns/proj", "strainmax", "vol_err", "vol_worst", "minV/V0",
         "sag/move", "rb");
  for (int i = 0; i < nrows && !fail; i++) print_row(&rows[i], csv);
  printf("(%d steps each; one core; sag/move: bar tip sag, spleen largest surface displacement, m)\n", steps);
  if (csv) fclose(csv);
  mesh_free(&spleen);
  return fail ? 1 : 0;
}
