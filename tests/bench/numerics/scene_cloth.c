/* SPDX-License-Identifier: Apache-2.0 */
/* S3: hanging cloth pinned at two corners, on the product's surface
 * mass-spring force system (mass_spring_create_surface: springs on the
 * triangle edges, so stretch and shear, no bending).
 *
 * A 30 x 30 vertex sheet, 0.29 m square (1 cm spacing, alternating
 * diagonals), 50 g, edge springs 200 N/m with 0.01 N s/m Kelvin-Voigt
 * damping, no home springs; it starts flat and horizontal, held at the two
 * corners of one edge, and falls under gravity for 0.3 s (0.2 s with
 * --quick; see below why not longer). Every integrator over the dt sweep, one sub-step per step;
 * reference: RK4 at 1/(30 2^11) s, checked by halving. PBD/XPBD are not run:
 * pbd.h takes tetrahedra only. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "numerics.h"
#include "physics/mass_spring.h"
#include "plot/plot.h"

#define CN 30
#define CH 0.01
#define SAMPLE (1.0 / 30)

static const integrator_kind_t KINDS[] = {INT_EXPLICIT_EULER, INT_SYMPLECTIC_EULER, INT_VERLET, INT_RK4,
                                          INT_IMPLICIT_EULER};
#define NKINDS 5

static double energy_cb(void *owner) { return mass_spring_energy(owner); }
static void free_cb(void *owner) {
  mass_spring_destroy(owner);
  free(owner);
}

static int cloth_mesh(mesh_t *m, verr_t *err) {
  if (mesh_alloc(m, CN * CN, 2 * (CN - 1) * (CN - 1), err)) return -1;
  for (size_t j = 0; j < CN; j++)
    for (size_t i = 0; i < CN; i++) {
      double *p = m->pos + 3 * (i + CN * j);
      p[0] = (double)i * CH;
      p[1] = (double)j * CH;
      p[2] = 0;
    }
  size_t t = 0;
  for (size_t j = 0; j + 1 < CN; j++)
    for (size_t i = 0; i + 1 < CN; i++) {
      uint32_t a = (uint32_t)(i + CN * j), b = a + 1, c = a + CN, d = c + 1;
      /* Alternating diagonals: no preferred shear direction. */
      uint32_t q[6] = {a, b, d, a, d, c};
      if ((i + j) & 1) q[0] = a, q[1] = b, q[2] = c, q[3] = b, q[4] = d, q[5] = c;
      memcpy(m->tris + 3 * t, q, sizeof q);
      t += 2;
    }
  return 0;
}

static sim_t *cloth_sim(const mesh_t *mesh, integrator_kind_t kind, verr_t *err) {
  mass_spring_t *ms = calloc(1, sizeof *ms);
  if (!ms) return verr_set(err, "out of memory"), NULL;
  ms_params_t p = {.mass = 0.05, .stiffness = 200, .damping = 0.01, .gravity = {0, 0, -9.81}};
  if (mass_spring_create_surface(ms, mesh, &p, err)) {
    free(ms);
    return NULL;
  }
  ms->inv_mass[0] = 0;      /* corner (0, 0) */
  ms->inv_mass[CN - 1] = 0; /* corner (L, 0) */
  ms->definite_jacobian = kind == INT_IMPLICIT_EULER;
  return sim_fs(&ms->fs, kind, 1, 1e-3, 200, energy_cb, free_cb, ms, err);
}

void scene_cloth(nb_t *nb) {
  /* 0.3 s: the fall to hanging. Later the sheet folds through itself (no
   * self-collision, no bending springs) and stops being a smooth problem:
   * halving the reference step then changed e_x by 3e-3 at 0.6 s and 2e-2
   * at 1 s, so no reference converges there. */
  const double T = nb->quick ? 0.2 : 0.3;
  const int NDT = nb->quick ? 8 : 10;
  verr_t err;
  mesh_t mesh;
  if (cloth_mesh(&mesh, &err)) {
    nb_skip(nb, "S3: %s", err.msg);
    return;
  }
  /* The swing sweeps a box about L x L x L. */
  double diag = (CN - 1) * CH * sqrt(3.0);
  double dt_ref = nb_dt(nb->quick ? 10 : 11);
  nb_progress("S3 hanging cloth (30x30, pinned at two corners): reference RK4 dt = 1/%.0f s, %.1f s", 1 / dt_ref, T);
  run_spec_t sp = {.dt = dt_ref, .T = T, .sample_dt = SAMPLE, .reps = 1, .blowup = 10 * diag};
  run_out_t ref, ref2;
  sim_t *s = cloth_sim(&mesh, INT_RK4, &err);
  if (!s || run_sim(s, &sp, &ref, &err)) {
    nb_skip(nb, "S3 reference: %s", err.msg);
    sim_destroy(s);
    mesh_free(&mesh);
    return;
  }
  double ref_self = NAN;
  if (!nb->quick) {
    sp.dt = dt_ref / 2;
    if (run_sim(s, &sp, &ref2, &err) == 0) {
      ref_self = ex_error(&ref.traj, &ref2.traj, s->mass, diag, NULL);
      run_out_free(&ref2);
    }
  }
  sim_destroy(s);
  nb_progress("S3: reference halving changes e_x by %.2e", ref_self);
  FILE *csv = nb_csv(nb, "s3_cloth.csv",
                     "integrator,dt,steps,stable,t_fail,e_max,e_end,step_us_median,step_us_p95,wall_s_per_sim_s,"
                     "force_evals_per_step,reference_halving_e_x");
  double dts[12], errs[NKINDS][12], cost[NKINDS][12];
  for (int ki = 0; ki < NKINDS; ki++) {
    for (int d = 0; d < NDT; d++) {
      double dt = nb_dt(d);
      dts[d] = dt;
      errs[ki][d] = cost[ki][d] = NAN;
      s = cloth_sim(&mesh, KINDS[ki], &err);
      if (!s) continue;
      run_out_t o;
      sp.dt = dt;
      sp.reps = 3;
      if (run_sim(s, &sp, &o, &err) == 0) {
        double e_end, e = ex_error(&o.traj, &ref.traj, s->mass, diag, &e_end);
        if (!o.stable) e = e_end = NAN;
        errs[ki][d] = e;
        cost[ki][d] = o.stable ? o.wall_per_sim_s : NAN;
        if (csv)
          fprintf(csv, "%s,%.9g,%zu,%d,%.4g,%.6e,%.6e,%.3f,%.3f,%.6e,%.2f,%.3e\n", integrator_name(KINDS[ki]), dt,
                  o.steps, o.stable, o.t_fail, e, e_end, o.step_us_median, o.step_us_p95, o.wall_per_sim_s,
                  o.evals_per_step, ref_self);
        nb_result(nb, "S3", "mass_spring_surface", integrator_name(KINDS[ki]), dt, 1, 1, "e_x", e, e_end, &o);
        run_out_free(&o);
      }
      sim_destroy(s);
    }
  }
  if (csv) fclose(csv);
  plot_t p;
  plot_init(&p, "S3 hanging cloth (30x30, two corners pinned, 0.3 s fall): work-precision",
            "wall time per simulated second (s, one core)", "e_x: max mass-weighted RMS error / bbox diagonal", 1, 1);
  p.pareto = 1;
  snprintf(p.empty_suffix, sizeof p.empty_suffix, " (all diverged)");
  for (int ki = 0; ki < NKINDS; ki++) {
    plot_series_t *se = plot_add(&p, integ_label(KINDS[ki]), (size_t)NDT, cost[ki], errs[ki], ki, ki, PLOT_LINE_SOLID);
    if (se) se->pareto = 1;
  }
  plot_note(&p, "mass_spring_surface force system, dt = 1/30 ... 1/%.0f s, one sub-step; diverged runs left out. "
                "Reference: RK4 at 1/%.0f s (halving it changes e_x by %.1e).",
            1 / nb_dt(NDT - 1), 1 / dt_ref, ref_self);
  nb_plot(nb, &p, "plot1_work_precision_S3.png");
  plot_free(&p);
  plot_init(&p, "S3 hanging cloth: error vs step", "time step dt (s)", "e_x: max mass-weighted RMS error / bbox diagonal",
            1, 1);
  snprintf(p.empty_suffix, sizeof p.empty_suffix, " (all diverged)");
  for (int ki = 0; ki < NKINDS; ki++) {
    double fx[12], fy[12];
    int nf = 0;
    for (int i = NDT - 1; i >= 0 && nf < 5; i--)
      if (errs[ki][i] > 1e-12 && errs[ki][i] < 0.05) fx[nf] = dts[i], fy[nf] = errs[ki][i], nf++;
    double slope = plot_loglog_slope((size_t)nf, fx, fy, 0, 1, NULL);
    char lab[112];
    if (isfinite(slope)) snprintf(lab, sizeof lab, "%s (slope %.2f)", integ_label(KINDS[ki]), slope);
    else snprintf(lab, sizeof lab, "%s", integ_label(KINDS[ki]));
    plot_add(&p, lab, (size_t)NDT, dts, errs[ki], ki, ki, PLOT_LINE_SOLID);
  }
  plot_note(&p, "Slopes over the five smallest steps with e_x in (1e-12, 0.05).");
  nb_plot(nb, &p, "plot2_error_vs_dt_S3.png");
  plot_free(&p);
  run_out_free(&ref);
  mesh_free(&mesh);
}
