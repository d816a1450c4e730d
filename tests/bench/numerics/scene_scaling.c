/* SPDX-License-Identifier: Apache-2.0 */
/* Plot 7: step time against vertex count (docs/numerics.md §4 plot 7, §7 "step cost
 * vs size: linear").
 *
 * Volumetric: bars of 90 to 11,520 nodes (same 2 cm spacing and material as
 * the S4 bar, so the same stable step) with mass_spring_tet (symplectic
 * Euler; implicit Euler with CG to 1e-3), PBD and XPBD (10 iterations), one
 * sub-step each. Surface: the organ meshes of assets/meshes (45 to 23,522
 * vertices) with mass_spring_surface and molecular through model_create,
 * product material defaults, one sub-step. Every point is the median of
 * enough steps to fill about 0.2 s (at least 20), gravity on, dt 1e-4 s (stable
 * for all of them). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bar.h"
#include "mesh_import.h"
#include "tet_mesh.h"
#ifdef NUMERICS_HAVE_MOLECULAR
#include "physics/molecular.h"
#endif
#include "plot/plot.h"
#include "vstats.h"
#include "vtime.h"

#define DT 1e-4

/* Median step time in us (NAN if a step failed). */
static double time_steps(sim_t *s, double budget_s) {
  double buf[4000];
  size_t n = 0;
  uint64_t start = vtime_mono_ns();
  while (n < 4000 && (n < 20 || (double)(vtime_mono_ns() - start) * 1e-9 < budget_s)) {
    uint64_t a = vtime_mono_ns();
    if (s->step(s, DT)) return NAN;
    buf[n++] = (double)(vtime_mono_ns() - a) * 1e-3;
  }
  return vstats_summarise(buf, n).median;
}

#ifdef NUMERICS_HAVE_MOLECULAR
static double mol_energy(void *owner) { return molecular_energy(owner); }
static void mol_free(void *owner) {
  molecular_destroy(owner);
  free(owner);
}

/* The molecular force system directly (molecular.h), material defaults of
 * scene.h, so its cost is measured whether or not model_create lists it. */
static sim_t *molecular_sim(const nb_t *nb, const char *organ, size_t *nverts, verr_t *err) {
  char path[1200];
  snprintf(path, sizeof path, "%s/meshes/%s.obj", nb->assets, organ);
  mesh_t mesh;
  if (mesh_import(path, &mesh, err)) return NULL;
  *nverts = mesh.nverts;
  molecular_t *m = calloc(1, sizeof *m);
  mol_params_t p = {.mass = 0.1, .bond_k = 30, .angle_k = 1e-3, .stretch_bend_k = 0, .bond_damping = 0.02,
                    .home_stiffness = 30, .home_damping = 0.005, .gravity = {0, 0, -9.81}};
  int rc = !m || molecular_create(m, &mesh, &p, err);
  mesh_free(&mesh);
  if (rc) {
    free(m);
    return NULL;
  }
  return sim_fs(&m->fs, INT_SYMPLECTIC_EULER, 1, 1e-3, 200, mol_energy, mol_free, m, err);
}
#endif

static sim_t *organ_sim(const nb_t *nb, const char *organ, const char *model, size_t *nverts, verr_t *err) {
#ifdef NUMERICS_HAVE_MOLECULAR
  if (!strcmp(model, "molecular")) return molecular_sim(nb, organ, nverts, err);
#endif
  char yaml[2048];
  static scene_t sc;
  snprintf(yaml, sizeof yaml, "scene: numerics_scaling\norgans:\n  - name: %s\n    mesh: %s/meshes/%s.obj\n", organ,
           nb->assets, organ);
  if (scene_load_string(yaml, "numerics_scaling", NULL, &sc, err)) return NULL;
  scene_organ_t *o = &sc.organs[0];
  snprintf(o->model, sizeof o->model, "%s", model);
  snprintf(o->integrator, sizeof o->integrator, "symplectic_euler");
  o->solver.substeps = 1;
  /* Every node integrated: the cost of a step when the whole organ moves
   * (regional sleeping would time an organ at rest as nearly free). */
  o->solver.region_force = 0;
  mesh_t mesh;
  if (mesh_import(o->mesh, &mesh, err)) return NULL;
  *nverts = mesh.nverts;
  model_params_t mp = {.cfg = o, .surface = &mesh, .gravity = {0, 0, -9.81}, .dt = DT, .tool_stiffness = 300};
  model_t *m = model_create(&mp, err);
  mesh_free(&mesh);
  if (!m) return NULL;
  return sim_model(m, err);
}

/* Mean edge length of the tetrahedra (each tet's six edges). */
static double mean_edge(const tet_mesh_t *t) {
  static const int E[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  double sum = 0;
  for (size_t i = 0; i < t->ntets; i++)
    for (int e = 0; e < 6; e++) {
      const double *a = t->x + 3 * (size_t)t->tets[4 * i + E[e][0]], *b = t->x + 3 * (size_t)t->tets[4 * i + E[e][1]];
      sum += sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
    }
  return t->ntets ? sum / (6.0 * (double)t->ntets) : NAN;
}

void scene_scaling(nb_t *nb) {
  static const size_t SIZES[][3] = {{10, 3, 3}, {20, 4, 4}, {30, 5, 5}, {40, 7, 7}, {60, 10, 10}, {80, 12, 12}};
  static const char *ORGANS[] = {"tissue_block", "spleen", "kidney", "gallbladder", "liver_large"};
  const int nsizes = nb->quick ? 4 : 6, norgans = nb->quick ? 3 : 5;
  const double budget = nb->quick ? 0.05 : 0.2;
  nb_progress("plot 7: step time vs size (%d bars, %d organ meshes)", nsizes, norgans);
  FILE *csv = nb_csv(nb, "plot7_step_time.csv", "model,setting,mesh,nodes,tets,step_us_median");
  enum { MS_SYM, MS_IMP, XPBD10, PBD10, SURF, MOL, OXPBD, OMS, NSER };
  static const char *LAB[NSER] = {"mass_spring_tet, symplectic Euler (bars)",
                                  "mass_spring_tet, implicit Euler, CG 1e-3 (bars)",
                                  "XPBD, 10 iterations (bars)",
                                  "PBD, 10 iterations (bars)",
                                  "mass_spring_surface, symplectic (organs)",
                                  "molecular, symplectic (organs, molecular.h)",
                                  "XPBD, 10 iterations (organ tets)",
                                  "mass_spring_tet, symplectic (organ tets)"};
  double xs[NSER][8], ys[NSER][8];
  int cnt[NSER] = {0};
  const double g[3] = {0, 0, -9.81};
  verr_t err;
  for (int i = 0; i < nsizes; i++) {
    bar_t b;
    if (bar_init(&b, SIZES[i][0], SIZES[i][1], SIZES[i][2], 0.02, &err)) continue;
    char mesh[48];
    snprintf(mesh, sizeof mesh, "bar %zux%zux%zu", SIZES[i][0], SIZES[i][1], SIZES[i][2]);
    for (int k = MS_SYM; k <= PBD10; k++) {
      sim_t *s = NULL;
      if (k == MS_SYM) s = bar_mass_spring(&b, INT_SYMPLECTIC_EULER, 1, 2e4, 0, g, NULL, 1e-3, &err);
      else if (k == MS_IMP) s = bar_mass_spring(&b, INT_IMPLICIT_EULER, 1, 2e4, 0, g, NULL, 1e-3, &err);
#ifdef NUMERICS_HAVE_PBD
      else s = bar_pbd(&b, k == XPBD10, 1, 10, 2e4, 0, g, NULL, &err);
#endif
      if (!s) continue;
      double us = time_steps(s, budget);
      sim_destroy(s);
      xs[k][cnt[k]] = (double)b.tm.nnodes;
      ys[k][cnt[k]++] = us;
      if (csv) fprintf(csv, "%s,1 sub-step,%s,%zu,%zu,%.3f\n", LAB[k], mesh, b.tm.nnodes, b.tm.ntets, us);
    }
    nb_progress("plot 7: %s (%zu nodes) done", mesh, b.tm.nnodes);
    bar_free(&b);
  }
  for (int i = 0; i < norgans; i++)
    for (int k = SURF; k <= MOL; k++) {
      size_t nv = 0;
      sim_t *s = organ_sim(nb, ORGANS[i], k == SURF ? "mass_spring_surface" : "molecular", &nv, &err);
      if (!s) {
        if (i == 0) nb_skip(nb, "plot 7 %s: %s", k == SURF ? "mass_spring_surface" : "molecular", err.msg);
        continue;
      }
      double us = time_steps(s, budget);
      sim_destroy(s);
      xs[k][cnt[k]] = (double)nv;
      ys[k][cnt[k]++] = us;
      if (csv) fprintf(csv, "%s,1 sub-step,%s,%zu,0,%.3f\n", LAB[k], ORGANS[i], nv, us);
    }
  /* Tetrahedral models on the organs: the volume mesh the product builds
   * (tet_mesh_build, automatic size), product material defaults. */
  for (int i = 0; i < norgans; i++) {
    char path[1200];
    snprintf(path, sizeof path, "%s/meshes/%s.obj", nb->assets, ORGANS[i]);
    mesh_t mesh;
    tet_mesh_t tm;
    tet_build_report_t rep;
    if (mesh_import(path, &mesh, &err)) continue;
    int rc = tet_mesh_build(&mesh, 0, &tm, NULL, &rep, &err);
    mesh_free(&mesh);
    if (rc) {
      nb_progress("plot 7: %s: %s", ORGANS[i], err.msg);
      continue;
    }
    for (int k = OXPBD; k <= OMS; k++) {
      sim_t *s = NULL;
#ifdef NUMERICS_HAVE_PBD
      if (k == OXPBD) s = tets_xpbd(&tm, 10, &err);
#endif
      if (k == OMS) s = tets_mass_spring(&tm, INT_SYMPLECTIC_EULER, &err);
      if (!s) continue;
      double us = time_steps(s, budget);
      sim_destroy(s);
      xs[k][cnt[k]] = (double)tm.nnodes;
      ys[k][cnt[k]++] = us;
      if (csv) fprintf(csv, "%s,1 sub-step,%s tets,%zu,%zu,%.3f\n", LAB[k], ORGANS[i], tm.nnodes, tm.ntets, us);
    }
#ifdef NUMERICS_HAVE_PBD
    /* §7 names a 711-node / 2,385-tet spleen: rebuild ours at the edge that
     * gives about as many tetrahedra (tet count ~ edge^-3) and time that. */
    if (!strcmp(ORGANS[i], "spleen") && mesh_import(path, &mesh, &err) == 0) {
      double edge = mean_edge(&tm) * cbrt((double)tm.ntets / 2385.0);
      tet_mesh_t t2;
      int ok = tet_mesh_build(&mesh, edge, &t2, NULL, &rep, &err) == 0;
      /* The builder's edge is its grid spacing, not the mean edge: correct
       * twice by the same cube law. */
      for (int it = 0; ok && it < 2 && fabs((double)t2.ntets / 2385.0 - 1) > 0.1; it++) {
        edge *= cbrt((double)t2.ntets / 2385.0);
        tet_mesh_free(&t2);
        ok = tet_mesh_build(&mesh, edge, &t2, NULL, &rep, &err) == 0;
      }
      if (ok) {
        sim_t *s = tets_xpbd(&t2, 10, &err);
        if (s) {
          double us = time_steps(s, 2 * budget);
          sim_destroy(s);
          nb_target(nb, "XPBD step, 10 iterations, 1 sub-step, spleen volume mesh of %zu nodes / %zu tets "
                        "(tet_mesh_build, edge %.1f mm): %.3f ms; target <= 0.5 ms (for 711 nodes / 2,385 tets)",
                    t2.nnodes, t2.ntets, edge * 1e3, us * 1e-3);
        }
        tet_mesh_free(&t2);
      }
      mesh_free(&mesh);
    }
#endif
    tet_mesh_free(&tm);
  }
  /* Organ meshes come in file order: sort those series by size. */
  for (int k = OXPBD; k <= OMS; k++)
    for (int a = 1; a < cnt[k]; a++)
      for (int c = a; c > 0 && xs[k][c] < xs[k][c - 1]; c--) {
        double tx = xs[k][c], ty = ys[k][c];
        xs[k][c] = xs[k][c - 1], ys[k][c] = ys[k][c - 1];
        xs[k][c - 1] = tx, ys[k][c - 1] = ty;
      }
  if (csv) fclose(csv);
  /* §7 targets that fall out of these timings. */
  for (int j = 0; j < cnt[SURF]; j++)
    if (xs[SURF][j] > 5000 && xs[SURF][j] < 6000)
      nb_target(nb, "mass-spring step, %.0f-vertex surface organ (gallbladder), 1 sub-step: %.3f ms; target <= 0.25 ms",
                xs[SURF][j], ys[SURF][j] * 1e-3);
  for (int j = 0; j < cnt[MOL]; j++)
    if (xs[MOL][j] > 5000 && xs[MOL][j] < 6000)
      nb_target(nb, "molecular model step, %.0f vertices, 1 sub-step: %.3f ms; target <= 1 ms", xs[MOL][j],
                ys[MOL][j] * 1e-3);
  for (int j = 0; j < cnt[MS_IMP]; j++)
    if (xs[MS_IMP][j] > 9000)
      nb_target(nb, "implicit Euler step (one linearised step, CG to 1e-3), %.0f-node bar: %.2f ms; target <= 25 ms "
                    "at 10k vertices",
                xs[MS_IMP][j], ys[MS_IMP][j] * 1e-3);
  for (int k = 0; k < NSER; k++) {
    if (cnt[k] < 3) continue;
    double slope = plot_loglog_slope((size_t)cnt[k], xs[k], ys[k], 0, INFINITY, NULL);
    nb_target(nb, "step cost vs size, %s: log-log slope %.2f over %.0f-%.0f nodes (linear = 1)", LAB[k], slope,
              xs[k][0], xs[k][cnt[k] - 1]);
  }
  plot_t p;
  plot_init(&p, "Plot 7: step time vs mesh size (one sub-step, one core)", "nodes (vertices)", "median step time (us)",
            1, 1);
  for (int k = 0; k < NSER; k++)
    if (cnt[k])
      plot_add(&p, LAB[k], (size_t)cnt[k], xs[k], ys[k], k, k, k == PBD10 ? PLOT_LINE_DASHED : PLOT_LINE_SOLID);
  /* A slope-1 guide through the symplectic mass-spring's middle point. */
  if (cnt[MS_SYM] >= 2) {
    int mid = cnt[MS_SYM] / 2;
    double c = ys[MS_SYM][mid] / xs[MS_SYM][mid];
    double gx[2] = {40, 30000}, gy[2] = {c * 40, c * 30000};
    plot_add(&p, "linear in size (guide)", 2, gx, gy, PLOT_GREY, -1, PLOT_LINE_DOTTED);
  }
  plot_note(&p, "Bars: 90-11,520 nodes at 2 cm spacing; organs: assets/meshes (45-23,522 vertices); organ tets: the "
                "volume meshes tet_mesh_build makes of them.");
  plot_note(&p, "Implicit Euler's cost also scales with its CG iteration count, which depends on size, stiffness and "
                "dt (here 1e-4 s).");
  plot_note(&p, "PBD (dashed) and XPBD do the same projections per iteration: their curves lie on each other.");
  nb_plot(nb, &p, "plot7_step_time_vs_size.png");
  plot_free(&p);
}
