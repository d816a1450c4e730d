/* SPDX-License-Identifier: Apache-2.0 */
/* Scenes on the benchmark's own force system (springnet.h), where every
 * integrator of integrator.h runs on forces we know exactly:
 *
 *   S1  one-DoF spring: m = 1 kg, k = 4 pi^2 N/m (period 1 s), 10 cm
 *       amplitude, no damping, no gravity. The exact solution
 *       x(t) = L0 + A cos(omega t) is both the model answer and the converged
 *       reference, so solver and model error coincide; e_x is scaled by the
 *       amplitude (a 1-DoF system has no meaningful bounding box).
 *   S2  hanging chain: 50 nodes, 2 cm links, the top node fixed, 10 g nodes
 *       and a 1 kg end node (100x), released horizontally under gravity, so
 *       it swings down with stiff links (k = 5e4 N/m) and a 100:1 mass ratio.
 *       Reference: RK4 at a tiny step, checked by halving it.
 *   Plot 6: energy of the chain over up to 1e6 steps at half the critical
 *       step of symplectic Euler. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "numerics.h"
#include "plot/plot.h"
#include "springnet.h"

static const integrator_kind_t KINDS[] = {INT_EXPLICIT_EULER, INT_SYMPLECTIC_EULER, INT_VERLET, INT_RK4,
                                          INT_IMPLICIT_EULER};
#define NKINDS 5
/* Implicit Euler as the product runs it: one linearised step, CG to 1e-3. */
#define CG_TOL 1e-3
#define CG_MAX 200

static double sn_energy(void *owner) { return springnet_energy(owner); }

static sim_t *sn_sim(springnet_t *sn, integrator_kind_t k, double cg_tol, verr_t *err) {
  springnet_reset(sn);
  return sim_fs(&sn->fs, k, 1, cg_tol, CG_MAX, sn_energy, NULL, sn, err);
}

static void row(nb_t *nb, const char *scene, const char *model, integrator_kind_t k, double dt, double err,
                double err_end, const run_out_t *o, const char *metric) {
  nb_result(nb, scene, model, integrator_name(k), dt, 1, 1, metric, err, err_end, o);
}

/* ---- S1 -------------------------------------------------------------------------- */

typedef struct s1_obs {
  double L0, prev, tprev;
  int have, done;
  double cross[32];
  int nc;
} s1_obs_t;

/* Down-crossings of x - L0 (linear interpolation between steps) give the
 * period. */
static void s1_before(sim_t *s, double t, void *ctx) {
  s1_obs_t *o = ctx;
  /* Timing repetitions restart at t = 0: log the first run only. */
  if (o->done || (o->have && t <= o->tprev)) {
    o->done = 1;
    return;
  }
  double u = s->x[3] - o->L0;
  if (o->have && o->prev > 0 && u <= 0 && o->nc < 32)
    o->cross[o->nc++] = o->tprev + (t - o->tprev) * o->prev / (o->prev - u);
  o->prev = u;
  o->tprev = t;
  o->have = 1;
}

static void s1_observe(sim_t *s, double t, double *extra, void *ctx) {
  (void)t;
  (void)ctx;
  extra[0] = s->energy(s);
}

static void scene_s1(nb_t *nb) {
  nb_progress("S1 one-DoF spring: 5 integrators x 8 steps");
  const double L0 = 1, A = 0.1, m = 1, omega = 2 * M_PI, k = omega * omega * m, T = 3, SAMPLE = 1.0 / 30;
  verr_t err;
  springnet_t sn;
  if (springnet_alloc(&sn, 2, 1, &err)) {
    nb_skip(nb, "S1: %s", err.msg);
    return;
  }
  sn.inv_mass[0] = 0;
  sn.mass[1] = m;
  sn.inv_mass[1] = 1 / m;
  sn.x[3] = L0;
  springnet_set_spring(&sn, 0, 0, 1, k, 0);
  sn.x[3] = L0 + A;
  springnet_mark_initial(&sn);
  /* The exact trajectory at the sample instants. */
  traj_t exact = {.n = 2, .ns = (size_t)llround(T / SAMPLE) + 1};
  exact.x = calloc(exact.ns * 6, sizeof(double));
  if (!exact.x) {
    springnet_free(&sn);
    return;
  }
  for (size_t j = 0; j < exact.ns; j++) exact.x[6 * j + 3] = L0 + A * cos(omega * (double)j * SAMPLE);
  const double weight[2] = {0, 1}; /* the fixed anchor carries no error */
  const int NDT = 8;
  double dts[8], errs[NKINDS][8], cost[NKINDS][8];
  FILE *csv = nb_csv(nb, "s1_spring.csv",
                     "integrator,dt,steps,stable,e_max,e_end,energy_drift,period_error,damping_ratio,step_us_median,"
                     "step_us_p95,wall_s_per_sim_s,force_evals_per_step");
  for (int ki = 0; ki < NKINDS; ki++) {
    for (int d = 0; d < NDT; d++) {
      double dt = nb_dt(d);
      dts[d] = dt;
      errs[ki][d] = cost[ki][d] = NAN;
      sim_t *s = sn_sim(&sn, KINDS[ki], CG_TOL, &err);
      if (!s) {
        nb_progress("S1: %s", err.msg);
        continue;
      }
      s1_obs_t ob = {.L0 = L0};
      run_spec_t sp = {.dt = dt,
                       .T = T,
                       .sample_dt = SAMPLE,
                       .reps = 5,
                       .blowup = 1e3,
                       .nextra = 1,
                       .observe = s1_observe,
                       .before_step = s1_before,
                       .ctx = &ob};
      run_out_t o;
      if (run_sim(s, &sp, &o, &err)) {
        nb_progress("S1: %s", err.msg);
        sim_destroy(s);
        continue;
      }
      double e_end, e = ex_error(&o.traj, &exact, weight, A, &e_end);
      double E0 = o.traj.extra[0], E1 = o.traj.extra[o.traj.ns - 1];
      double drift = fabs(E1 - E0) / E0;
      double period = ob.nc >= 2 ? (ob.cross[ob.nc - 1] - ob.cross[0]) / (ob.nc - 1) : NAN;
      double zeta = -log(E1 / E0) / (2 * omega * T);
      if (!o.stable) e = e_end = drift = period = zeta = NAN;
      errs[ki][d] = e;
      cost[ki][d] = o.wall_per_sim_s;
      if (csv)
        fprintf(csv, "%s,%.9g,%zu,%d,%.6e,%.6e,%.6e,%.6e,%.6e,%.4f,%.4f,%.6e,%.3f\n", integrator_name(KINDS[ki]), dt,
                o.steps, o.stable, e, e_end, drift, period - 1.0, zeta, o.step_us_median, o.step_us_p95,
                o.wall_per_sim_s, o.evals_per_step);
      row(nb, "S1", "spring_1dof", KINDS[ki], dt, e, e_end, &o, "e_x/A");
      run_out_free(&o);
      sim_destroy(s);
    }
  }
  if (csv) fclose(csv);

  plot_t p;
  plot_init(&p, "S1 one-DoF spring (undamped, period 1 s, 3 s): error vs step", "time step dt (s)",
            "max position error / amplitude", 1, 1);
  for (int ki = 0; ki < NKINDS; ki++) {
    /* The asymptotic range only: round-off below, O(1) errors above. */
    size_t used;
    double slope = plot_loglog_slope(NDT, dts, errs[ki], 1e-11, 0.3, &used);
    char lab[112];
    if (isfinite(slope))
      snprintf(lab, sizeof lab, "%s (slope %.2f)", integ_label(KINDS[ki]), slope);
    else
      snprintf(lab, sizeof lab, "%s (no fit)", integ_label(KINDS[ki]));
    plot_add(&p, lab, NDT, dts, errs[ki], ki, ki, PLOT_LINE_SOLID);
  }
  plot_note(&p, "Slope: least squares of log error on log dt over the points with error in [1e-11, 0.3].");
  plot_note(
      &p, "Explicit Euler gains energy every step (amplitude x %.2f per period at 1/30 s): its error grows with time.",
      pow(1 + (omega / 30) * (omega / 30), 15));
  nb_plot(nb, &p, "plot2_error_vs_dt_S1.png");
  plot_free(&p);

  plot_init(&p, "S1 one-DoF spring: work-precision", "wall time per simulated second (s, one core)",
            "max position error / amplitude", 1, 1);
  p.pareto = 1;
  snprintf(p.empty_suffix, sizeof p.empty_suffix, " (all diverged)");
  for (int ki = 0; ki < NKINDS; ki++) {
    plot_series_t *se = plot_add(&p, integ_label(KINDS[ki]), NDT, cost[ki], errs[ki], ki, ki, PLOT_LINE_SOLID);
    if (se) se->pareto = 1;
  }
  plot_note(&p,
            "Points: dt = 1/30 ... 1/3840 s. A 1-DoF step costs nanoseconds, so loop overhead is part of the cost.");
  nb_plot(nb, &p, "plot1_work_precision_S1.png");
  plot_free(&p);
  free(exact.x);
  springnet_free(&sn);
}

/* ---- S2 -------------------------------------------------------------------------- */

#define CHAIN_N 50
#define CHAIN_LINK 0.02
#define CHAIN_M 0.01
#define CHAIN_END_M 1.0
#define CHAIN_K 5e4

static int chain_build(springnet_t *sn, int gravity, verr_t *err) {
  if (springnet_alloc(sn, CHAIN_N, CHAIN_N - 1, err)) return -1;
  for (size_t i = 0; i < CHAIN_N; i++) {
    sn->x[3 * i] = (double)i * CHAIN_LINK;
    sn->mass[i] = i == CHAIN_N - 1 ? CHAIN_END_M : CHAIN_M;
    sn->inv_mass[i] = i == 0 ? 0 : 1 / sn->mass[i];
  }
  for (size_t e = 0; e + 1 < CHAIN_N; e++) springnet_set_spring(sn, e, (uint32_t)e, (uint32_t)e + 1, CHAIN_K, 0);
  if (gravity) sn->gravity[2] = -9.81;
  /* Heights from the lowest reachable point, so E0 > 0 is the scale of |dE|. */
  sn->z_ref = -(CHAIN_N - 1) * CHAIN_LINK * 1.1;
  springnet_mark_initial(sn);
  return 0;
}

#ifdef NUMERICS_HAVE_PBD
/* The same chain as XPBD distance constraints (pbd_create_edges), compliance
 * 1/k: the same undamped spring network, so it shares the RK4 reference. */
static sim_t *chain_xpbd(const springnet_t *sn, int substeps, verr_t *err) {
  uint32_t edges[2 * (CHAIN_N - 1)];
  for (uint32_t e = 0; e + 1 < CHAIN_N; e++) edges[2 * e] = e, edges[2 * e + 1] = e + 1;
  pbd_params_t p = {.mode = PBD_MODE_XPBD,
                    .mass = CHAIN_M * CHAIN_N,
                    .distance_compliance = 1 / CHAIN_K,
                    .gravity = {0, 0, -9.81},
                    .substeps = substeps,
                    .iterations = 1};
  pbd_t *s = calloc(1, sizeof *s);
  if (!s) return verr_set(err, "out of memory"), NULL;
  if (pbd_create_edges(s, CHAIN_N, sn->x0, CHAIN_N - 1, edges, &p, err)) {
    free(s);
    return NULL;
  }
  for (size_t i = 0; i < CHAIN_N; i++) pbd_set_node_mass(s, i, sn->mass[i]);
  pbd_fix_node(s, 0);
  return sim_pbd(s, err);
}
#endif

static void energy_observe(sim_t *s, double t, double *extra, void *ctx) {
  (void)t;
  (void)ctx;
  extra[0] = s->energy(s);
}

static void scene_s2(nb_t *nb) {
  const double T = nb->quick ? 0.5 : 1.0, SAMPLE = 1.0 / 30;
  /* The chain's links are stiff: explicit schemes need about 1/2200 s, so
   * the sweep goes below 1/3840 s to show their converging branch. */
  const int NDT = nb->quick ? 8 : 11;
  nb_progress("S2 hanging chain (50 nodes, end mass 100x): 5 integrators x %d steps, %.1f s", NDT, T);
  verr_t err;
  springnet_t sn;
  if (chain_build(&sn, 1, &err)) {
    nb_skip(nb, "S2: %s", err.msg);
    return;
  }
  double lam = springnet_lambda_max(&sn, 400), omega_max = sqrt(lam);
  double diag = (CHAIN_N - 1) * CHAIN_LINK * sqrt(2.0); /* the swing's box: length x length */
  /* Reference: RK4 at 1/(30 2^12) s, and at half that to show it converged. */
  double dt_ref = nb_dt(nb->quick ? 10 : 12);
  run_out_t ref, ref2;
  sim_t *s = sn_sim(&sn, INT_RK4, CG_TOL, &err);
  run_spec_t sp = {
      .dt = dt_ref, .T = T, .sample_dt = SAMPLE, .reps = 1, .blowup = 100, .nextra = 1, .observe = energy_observe};
  if (!s || run_sim(s, &sp, &ref, &err)) {
    nb_skip(nb, "S2 reference: %s", err.msg);
    sim_destroy(s);
    springnet_free(&sn);
    return;
  }
  sp.dt = dt_ref / 2;
  int have2 = run_sim(s, &sp, &ref2, &err) == 0;
  sim_destroy(s);
  double ref_self = have2 ? ex_error(&ref.traj, &ref2.traj, sn.mass, diag, NULL) : NAN;
  if (have2) run_out_free(&ref2);
  nb_progress("S2 reference RK4 dt=1/%.0f: halving changes e_x by %.2e (omega_max %.0f rad/s, 2/omega %.3g s)",
              1 / dt_ref, ref_self, omega_max, 2 / omega_max);
  FILE *csv = nb_csv(nb, "s2_chain.csv",
                     "integrator,dt,steps,stable,t_fail,e_max,e_end,energy_drift,step_us_median,step_us_p95,"
                     "wall_s_per_sim_s,force_evals_per_step,reference,reference_halving_e_x");
  double dts[11], errs[NKINDS][11], cost[NKINDS][11];
  for (int ki = 0; ki < NKINDS; ki++)
    for (int d = 0; d < NDT; d++) {
      double dt = nb_dt(d);
      dts[d] = dt;
      errs[ki][d] = cost[ki][d] = NAN;
      s = sn_sim(&sn, KINDS[ki], CG_TOL, &err);
      run_out_t o;
      sp.dt = dt;
      sp.reps = 3;
      if (!s || run_sim(s, &sp, &o, &err)) {
        nb_progress("S2: %s", err.msg);
        sim_destroy(s);
        continue;
      }
      double e_end, e = ex_error(&o.traj, &ref.traj, sn.mass, diag, &e_end);
      double E0 = o.traj.extra[0], drift = fabs(o.traj.extra[o.traj.ns - 1] - E0) / E0;
      if (!o.stable) e = e_end = drift = NAN;
      errs[ki][d] = e;
      cost[ki][d] = o.stable ? o.wall_per_sim_s : NAN;
      if (csv)
        fprintf(csv, "%s,%.9g,%zu,%d,%.4g,%.6e,%.6e,%.6e,%.3f,%.3f,%.6e,%.2f,rk4 dt=1/%.0f,%.3e\n",
                integrator_name(KINDS[ki]), dt, o.steps, o.stable, o.t_fail, e, e_end, drift, o.step_us_median,
                o.step_us_p95, o.wall_per_sim_s, o.evals_per_step, 1 / dt_ref, ref_self);
      row(nb, "S2", "chain_springs", KINDS[ki], dt, e, e_end, &o, "e_x");
      run_out_free(&o);
      sim_destroy(s);
    }
  /* XPBD at the 60 Hz scene step, 1 iteration, sub-steps 1..64. */
  static const int SUBS[] = {1, 2, 4, 8, 16, 32, 64};
  const int NSUB = nb->quick ? 5 : 7;
  double xs_dt[7], xs_err[7], xs_cost[7];
#ifdef NUMERICS_HAVE_PBD
  nb_progress("S2: XPBD chain (edge constraints, compliance 1/k) at 1/60 s, 1 iteration, sub-steps 1..%d",
              SUBS[NSUB - 1]);
  for (int i = 0; i < NSUB; i++) {
    const double dt60 = 1.0 / 60;
    xs_dt[i] = dt60 / SUBS[i];
    xs_err[i] = xs_cost[i] = NAN;
    s = chain_xpbd(&sn, SUBS[i], &err);
    run_out_t o;
    sp.dt = dt60;
    sp.reps = 3;
    if (!s || run_sim(s, &sp, &o, &err)) {
      nb_progress("S2 XPBD: %s", err.msg);
      sim_destroy(s);
      continue;
    }
    double e_end, e = ex_error(&o.traj, &ref.traj, sn.mass, diag, &e_end);
    /* pbd_energy measures heights from z = 0, where the chain starts: E0 is
     * 0. Scale the drift by the energy above the lowest reachable point, as
     * the springnet's energy does (z_ref). */
    double off = 0;
    for (size_t k = 1; k < CHAIN_N; k++) off += sn.mass[k] * 9.81 * -sn.z_ref;
    double E0 = o.traj.extra[0], drift = fabs(o.traj.extra[o.traj.ns - 1] - E0) / (E0 + off);
    if (!o.stable) e = e_end = drift = NAN;
    xs_err[i] = e;
    xs_cost[i] = o.stable ? o.wall_per_sim_s : NAN;
    if (csv)
      fprintf(csv, "xpbd_%dsub_1it,%.9g,%zu,%d,%.4g,%.6e,%.6e,%.6e,%.3f,%.3f,%.6e,%.2f,rk4 dt=1/%.0f,%.3e\n", SUBS[i],
              dt60, o.steps, o.stable, o.t_fail, e, e_end, drift, o.step_us_median, o.step_us_p95, o.wall_per_sim_s,
              o.evals_per_step, 1 / dt_ref, ref_self);
    nb_result(nb, "S2", "xpbd_chain", "gauss_seidel", dt60, SUBS[i], 1, "e_x", e, e_end, &o);
    run_out_free(&o);
    sim_destroy(s);
  }
#else
  for (int i = 0; i < NSUB; i++) xs_dt[i] = xs_err[i] = xs_cost[i] = NAN;
#endif
  if (csv) fclose(csv);

  plot_t p;
  plot_init(&p, "S2 hanging chain, 50 nodes, end mass 100x: error vs step", "time step dt (s)",
            "e_x: max mass-weighted RMS error / bbox diagonal", 1, 1);
  snprintf(p.empty_suffix, sizeof p.empty_suffix, " (all diverged)");
  for (int ki = 0; ki < NKINDS; ki++) {
    size_t used;
    double slope = plot_loglog_slope((size_t)NDT, dts, errs[ki], 1e-10, 0.05, &used);
    char lab[112];
    if (isfinite(slope))
      snprintf(lab, sizeof lab, "%s (slope %.2f)", integ_label(KINDS[ki]), slope);
    else
      snprintf(lab, sizeof lab, "%s", integ_label(KINDS[ki]));
    plot_add(&p, lab, (size_t)NDT, dts, errs[ki], ki, ki, PLOT_LINE_SOLID);
  }
  plot_note(&p, "Missing points diverged. Symplectic/Verlet need dt < 2/omega_max = %.2g s; RK4 < 2 sqrt(2)/omega_max.",
            2 / omega_max);
  plot_note(&p,
            "Reference: RK4 at dt = 1/%.0f s (halving it changes e_x by %.1e). Slope fitted on e_x in [1e-10, 0.05].",
            1 / dt_ref, ref_self);
  {
    size_t used;
    double slope = plot_loglog_slope((size_t)NSUB, xs_dt, xs_err, 1e-10, 0.05, &used);
    char lab[112];
    if (isfinite(slope))
      snprintf(lab, sizeof lab, "XPBD, 60 Hz, 1 it, vs sub-step dt/n (slope %.2f)", slope);
    else
      snprintf(lab, sizeof lab, "XPBD, 60 Hz, 1 iteration, vs sub-step dt/n");
    plot_add(&p, lab, (size_t)NSUB, xs_dt, xs_err, 5, 5, PLOT_LINE_DASHED);
  }
  plot_note(&p,
            "XPBD: the same chain as distance constraints of compliance 1/k (pbd_create_edges), 60 Hz scene step "
            "with 1..%d sub-steps of 1 iteration, plotted at the sub-step length.",
            SUBS[NSUB - 1]);
  nb_plot(nb, &p, "plot2_error_vs_dt_S2.png");
  plot_free(&p);

  plot_init(&p, "S2 hanging chain: work-precision", "wall time per simulated second (s, one core)",
            "e_x: max mass-weighted RMS error / bbox diagonal", 1, 1);
  p.pareto = 1;
  snprintf(p.empty_suffix, sizeof p.empty_suffix, " (all diverged)");
  for (int ki = 0; ki < NKINDS; ki++) {
    plot_series_t *se = plot_add(&p, integ_label(KINDS[ki]), (size_t)NDT, cost[ki], errs[ki], ki, ki, PLOT_LINE_SOLID);
    if (se) se->pareto = 1;
  }
  {
    plot_series_t *se =
        plot_add(&p, "XPBD, 60 Hz, 1 iteration, sub-steps 1-64", (size_t)NSUB, xs_cost, xs_err, 5, 5, PLOT_LINE_SOLID);
    if (se) se->pareto = 1;
  }
  plot_note(&p,
            "Points: dt = 1/30 ... 1/%.0f s, one sub-step each; XPBD at 60 Hz with 1-%d sub-steps; diverged runs are "
            "left out.",
            1 / nb_dt(NDT - 1), SUBS[NSUB - 1]);
  nb_plot(nb, &p, "plot1_work_precision_S2.png");
  plot_free(&p);
  run_out_free(&ref);
  springnet_free(&sn);
}

/* ---- plot 6: energy over many steps ------------------------------------------------ */

static void scene_energy(nb_t *nb) {
  const long NSTEPS = nb->quick ? 10000 : 1000000;
  verr_t err;
  springnet_t sn;
  if (chain_build(&sn, 1, &err)) return;
  double omega_max = sqrt(springnet_lambda_max(&sn, 400));
  double h = 0.5 * 2 / omega_max;
  nb_progress("plot 6: chain energy over %ld steps at dt = %.3g s (half the symplectic limit)", NSTEPS, h);
  FILE *csv = nb_csv(nb, "plot6_energy.csv", "integrator,step,time_s,rel_energy_error");
  plot_t p;
  plot_init(&p, "", "step", "|E - E0| / E0", 1, 1);
  snprintf(p.title, sizeof p.title, "Energy of the S2 chain over %.0e steps, dt = 1/2 x 2/omega_max = %.3g s",
           (double)NSTEPS, h);
  const int NPTS = 240;
  double xs[240], ys[240];
  double final_err[NKINDS];
  for (int ki = 0; ki < NKINDS; ki++) {
    final_err[ki] = NAN;
    sim_t *s = sn_sim(&sn, KINDS[ki], CG_TOL, &err);
    if (!s) continue;
    double E0 = springnet_energy(&sn);
    int np = 0;
    long next = 1;
    int blew = 0;
    for (long st = 1; st <= NSTEPS; st++) {
      int rc = s->step(s, h);
      if (st == next || st == NSTEPS || rc) {
        double E = springnet_energy(&sn), rel = fabs(E - E0) / E0;
        /* An exact 0 (early steps) has no place on a log axis: show it at the
         * rounding floor instead of leaving a gap. */
        if (rel < 1e-16) rel = 1e-16;
        if (rc || !isfinite(rel) || rel > 1e3) blew = 1;
        if (np < NPTS && !blew) {
          xs[np] = (double)st;
          ys[np] = rel;
          np++;
          if (csv) fprintf(csv, "%s,%ld,%.6f,%.6e\n", integrator_name(KINDS[ki]), st, st * h, rel);
        }
        /* Log-spaced samples: 40 per decade. */
        while (next <= st)
          next = (long)ceil((double)next * 1.0593) > next ? (long)ceil((double)next * 1.0593) : next + 1;
        if (blew) break;
        final_err[ki] = rel;
      }
    }
    char lab[112];
    if (blew)
      snprintf(lab, sizeof lab, "%s (diverged)", integ_label(KINDS[ki]));
    else
      snprintf(lab, sizeof lab, "%s", integ_label(KINDS[ki]));
    plot_add(&p, lab, (size_t)np, xs, ys, ki, -1, PLOT_LINE_SOLID);
    sim_destroy(s);
  }
  if (csv) fclose(csv);
  plot_note(&p, "Undamped chain swinging under gravity, E0 measured from the lowest reachable height; values under "
                "1e-16 (rounding) are drawn at 1e-16.");
  plot_note(&p, "Symplectic Euler and Verlet oscillate without trend; RK4 and implicit Euler lose energy; explicit "
                "Euler gains it.");
  nb_plot(nb, &p, "plot6_energy_S2.png");
  plot_free(&p);
  for (int ki = 0; ki < NKINDS; ki++)
    nb_progress("plot 6: %-16s |E-E0|/E0 after %ld steps: %.3e", integrator_name(KINDS[ki]), NSTEPS, final_err[ki]);
  springnet_free(&sn);
}

void scene_spring(nb_t *nb) { scene_s1(nb); }

void scene_chain(nb_t *nb) {
  scene_s2(nb);
  scene_energy(nb);
}
