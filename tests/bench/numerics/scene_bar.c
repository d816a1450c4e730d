/* SPDX-License-Identifier: Apache-2.0 */
/* Bar scenes (bar.h: 30 x 5 x 5 nodes, 2 cm spacing, 0.58 x 0.08 x 0.08 m,
 * 3.7 kg rubber-like, edge springs k = 2e4 N/m, x = 0 face fixed):
 *
 *   S4  cantilever released straight under gravity (it swings down to a
 *       sag of about 13 % of its length);
 *   S5  360 degree twist about its axis, released (no gravity);
 *   S6  uniaxial stretch to 1.5x, released (no gravity).
 *
 * Each runs mass_spring_tet with every integrator over the dt sweep (one
 * sub-step per step), XPBD and PBD over sub-steps and iterations at the
 * 60 Hz step; S4 is undamped, S5 and S6 have light ground damping (see
 * SCENES below for why). The converged reference is the spring
 * network integrated by RK4 at a tiny step (halving it is reported); XPBD
 * solves the same network (distance compliance 1/k, volume constraints
 * off), so it is measured against the same reference. PBD converges to the
 * rigid bar as sub-steps grow, whatever its stiffness, so its reference is
 * PBD at its finest setting (256 sub-steps).
 *
 * Also here: plot 4 (tip sag of a damped bar vs iterations and dt, PBD and
 * XPBD against the static solution), plot 5 (XPBD sub-steps vs iterations at
 * equal cost), the XPBD BarDemo timing (docs/numerics.md §7) and the model error of
 * the spring network against beam theory with its measured Young's modulus. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bar.h"
#include "physics/mass_spring.h"
#include "plot/plot.h"
#include "vtime.h"

#define BAR_H 0.02
#define BAR_K 2e4
#define SAMPLE (1.0 / 30)

static const integrator_kind_t KINDS[] = {INT_EXPLICIT_EULER, INT_SYMPLECTIC_EULER, INT_VERLET, INT_RK4,
                                          INT_IMPLICIT_EULER};
#define NKINDS 5
#define MAXPTS 16

#ifdef NUMERICS_HAVE_PBD
static const int SUBSTEPS[] = {1, 2, 4, 8, 16, 32, 64};
static const int ITERS[] = {1, 2, 5, 10, 20, 50};
#endif
#define NSUB 7
#define NITER 6

enum { INIT_REST, INIT_TWIST, INIT_STRETCH };

typedef struct bar_scene {
  const char *id, *title;
  int gravity, init;
  double T, T_quick;  /* simulated s */
  double c_ground;    /* N s/m per node */
  int ref_k;          /* reference step 1/(30 2^ref_k) */
} bar_scene_t;

typedef struct series {
  char label[96];
  int color, marker, n;
  double x[MAXPTS], err[MAXPTS], cost[MAXPTS];
} series_t;

static void initial_state(const bar_t *b, int init, double *x) {
  size_t n = b->tm.nnodes;
  memcpy(x, b->tm.x, 3 * n * sizeof *x);
  double L = (double)(b->nx - 1) * b->h, yc = 0.5 * (double)(b->ny - 1) * b->h, zc = 0.5 * (double)(b->nz - 1) * b->h;
  for (size_t i = 0; i < n; i++) {
    double *p = x + 3 * i;
    if (init == INIT_STRETCH) p[0] *= 1.5;
    if (init == INIT_TWIST) {
      double a = 2 * M_PI * p[0] / L, y = p[1] - yc, z = p[2] - zc;
      p[1] = yc + cos(a) * y - sin(a) * z;
      p[2] = zc + sin(a) * y + cos(a) * z;
    }
  }
}

static void observe_bar(sim_t *s, double t, double *extra, void *ctx) {
  (void)t;
  const bar_t *b = ctx;
  extra[0] = s->energy(s);
  bar_measures(b, s->x, &extra[1], &extra[2], &extra[3], &extra[4]);
  extra[5] = s->x[3 * b->tip + 2] - b->tm.x[3 * b->tip + 2];
}
#define NEXTRA 6

static run_spec_t bar_spec(const bar_t *b, double dt, double T) {
  return (run_spec_t){.dt = dt, .T = T, .sample_dt = SAMPLE, .reps = 3, .blowup = 10 * b->diag, .nextra = NEXTRA,
                      .observe = observe_bar, .ctx = (void *)b};
}

static void csv_line(FILE *csv, const char *scene, const char *model, const char *integ, double dt, int sub, int it,
                     const run_out_t *o, double e, double e_end, const char *ref) {
  if (!csv) return;
  const double *last = o->traj.extra + (o->traj.ns - 1) * o->traj.nextra;
  double E0 = o->traj.extra[0], drift = isfinite(E0) && E0 != 0 ? fabs(last[0] - E0) / fabs(E0) : NAN;
  if (!o->stable) e = e_end = drift = NAN;
  fprintf(csv, "%s,%s,%s,%.9g,%d,%d,%d,%.4g,%.6e,%.6e,%.4e,%.5f,%.0f,%.5f,%.5f,%.3f,%.3f,%.6e,%.1f,%s\n", scene, model,
          integ, dt, sub, it, o->stable, o->t_fail, e, e_end, drift, o->stable ? last[1] : NAN,
          o->stable ? last[2] : NAN, o->stable ? last[3] : NAN, o->stable ? last[4] : NAN, o->step_us_median,
          o->step_us_p95, o->wall_per_sim_s, o->evals_per_step, ref);
}

static const char *CSV_HEADER =
    "scene,model,integrator,dt,substeps,iterations,stable,t_fail,e_max,e_end,energy_drift,min_vol_ratio_end,"
    "inverted_end,worst_vol_err_end,max_strain_end,step_us_median,step_us_p95,wall_s_per_sim_s,evals_per_step,"
    "reference";

static void add_point(series_t *s, double x, double e, const run_out_t *o) {
  if (s->n >= MAXPTS) return;
  s->x[s->n] = x;
  s->err[s->n] = o->stable ? e : NAN;
  s->cost[s->n] = o->stable ? o->wall_per_sim_s : NAN;
  s->n++;
}

/* Runs that ended with inverted tetrahedra, for a note under the plots. */
static char inverted_note[300];

/* One run compared with a reference; returns e_max (NAN if unstable). */
static double measure(nb_t *nb, FILE *csv, const bar_t *b, sim_t *s, double dt, double T, const traj_t *ref,
                      const char *scene, const char *model, const char *integ, const char *refname, series_t *se,
                      double xval) {
  verr_t err;
  run_out_t o;
  run_spec_t sp = bar_spec(b, dt, T);
  if (run_sim(s, &sp, &o, &err)) {
    nb_progress("%s %s: %s", scene, model, err.msg);
    return NAN;
  }
  double e_end, e = ex_error(&o.traj, ref, s->mass, b->diag, &e_end);
  csv_line(csv, scene, model, integ, dt, s->substeps, s->iterations, &o, e, e_end, refname);
  nb_result(nb, scene, model, integ, dt, s->substeps, s->iterations, "e_x", e, e_end, &o);
  if (se) add_point(se, xval, e, &o);
  const double *last = o.traj.extra + (o.traj.ns - 1) * o.traj.nextra;
  if (o.stable && last[2] > 0) {
    char item[80];
    if (!strcmp(model, "mass_spring_tet"))
      snprintf(item, sizeof item, "%s 1/%.0f s: %.0f", integ, 1 / dt, last[2]);
    else
      snprintf(item, sizeof item, "%s %dx%d: %.0f", !strcmp(model, "xpbd") ? "XPBD" : "PBD", s->substeps,
               s->iterations, last[2]);
    size_t len = strlen(inverted_note);
    if (!strstr(inverted_note, item) && len + strlen(item) + 2 < sizeof inverted_note)
      snprintf(inverted_note + len, sizeof inverted_note - len, "%s%s", len ? ", " : "", item);
  }
  int stable = o.stable;
  run_out_free(&o);
  return stable ? e : NAN;
}

static void plot_series(plot_t *p, const series_t *s, int use_cost, int pareto) {
  double xs[MAXPTS];
  for (int i = 0; i < s->n; i++) xs[i] = use_cost ? s->cost[i] : s->x[i];
  plot_series_t *ps = plot_add(p, s->label, (size_t)s->n, xs, s->err, s->color, s->marker, PLOT_LINE_SOLID);
  if (ps) ps->pareto = pareto;
}

/* ---- one bar scene ---------------------------------------------------------------- */

static void bar_scene(nb_t *nb, bar_t *b, const bar_scene_t *sc, FILE *csv) {
  const double T = nb->quick ? sc->T_quick : sc->T;
  const int NDT = nb->quick ? 8 : 10;
  const double g0[3] = {0, 0, 0}, gz[3] = {0, 0, -9.81};
  const double *g = sc->gravity ? gz : g0;
  verr_t err;
  double *x0 = malloc(3 * b->tm.nnodes * sizeof *x0);
  if (!x0) return;
  initial_state(b, sc->init, x0);
  inverted_note[0] = 0;

  /* Reference: the spring network by RK4 at 1/(30 2^k) s, and at half that. */
  double dt_ref = nb_dt(nb->quick ? sc->ref_k - 1 : sc->ref_k);
  nb_progress("%s %s: reference (RK4 dt = 1/%.0f s, %.1f s simulated)", sc->id, sc->title, 1 / dt_ref, T);
  sim_t *s = bar_mass_spring(b, INT_RK4, 1, BAR_K, sc->c_ground, g, x0, 1e-3, &err);
  run_out_t ref, ref2;
  run_spec_t sp = bar_spec(b, dt_ref, T);
  sp.reps = 1;
  if (!s || run_sim(s, &sp, &ref, &err)) {
    nb_skip(nb, "%s: reference failed: %s", sc->id, err.msg);
    sim_destroy(s);
    free(x0);
    return;
  }
  double ref_self = NAN;
  if (!nb->quick) {
    sp.dt = dt_ref / 2;
    if (run_sim(s, &sp, &ref2, &err) == 0) {
      ref_self = ex_error(&ref.traj, &ref2.traj, s->mass, b->diag, NULL);
      run_out_free(&ref2);
    }
  }
  sim_destroy(s);
  if (!ref.stable) {
    nb_skip(nb, "%s: the reference run diverged at t = %.3f s", sc->id, ref.t_fail);
    run_out_free(&ref);
    free(x0);
    return;
  }
  char refname[96];
  snprintf(refname, sizeof refname, "rk4 dt=1/%.0f (halving: e_x %.1e)", 1 / dt_ref, ref_self);
  nb_progress("%s: reference halving changes e_x by %.2e", sc->id, ref_self);

  series_t ms[NKINDS];
  memset(ms, 0, sizeof ms);
  for (int ki = 0; ki < NKINDS; ki++) {
    snprintf(ms[ki].label, sizeof ms[ki].label, "mass-spring, %s", integ_label(KINDS[ki]));
    ms[ki].color = ki;
    ms[ki].marker = ki;
    nb_progress("%s: mass_spring_tet %s x %d steps", sc->id, integrator_name(KINDS[ki]), NDT);
    for (int d = 0; d < NDT; d++) {
      double dt = nb_dt(d);
      s = bar_mass_spring(b, KINDS[ki], 1, BAR_K, sc->c_ground, g, x0, 1e-3, &err);
      if (!s) {
        nb_progress("%s: %s", sc->id, err.msg);
        continue;
      }
      measure(nb, csv, b, s, dt, T, &ref.traj, sc->id, "mass_spring_tet", integrator_name(KINDS[ki]), refname,
              &ms[ki], dt);
      sim_destroy(s);
    }
  }

  series_t xs_sub = {.color = 5, .marker = 5}, xs_it = {.color = 6, .marker = 6}, pb_sub = {.color = 9, .marker = 1},
           pb_it = {.color = 8, .marker = 3};
  snprintf(xs_sub.label, sizeof xs_sub.label, "XPBD, 1 iteration, sub-steps 1-64");
  snprintf(xs_it.label, sizeof xs_it.label, "XPBD, 1 sub-step, iterations 1-50");
  snprintf(pb_sub.label, sizeof pb_sub.label, "PBD, 1 iteration, sub-steps (vs PBD 256 sub)");
  snprintf(pb_it.label, sizeof pb_it.label, "PBD, 1 sub-step, iterations (vs PBD 256 sub)");
  int have_pbd = 0;
#ifdef NUMERICS_HAVE_PBD
  have_pbd = 1;
  const double dt60 = 1.0 / 60;
  nb_progress("%s: XPBD at 1/60 s: sub-steps 1..64 (1 iteration), iterations 1..50 (1 sub-step)", sc->id);
  for (int i = 0; i < NSUB; i++) {
    s = bar_pbd(b, 1, SUBSTEPS[i], 1, BAR_K, sc->c_ground, g, x0, &err);
    if (!s) {
      nb_progress("%s: %s", sc->id, err.msg);
      break;
    }
    measure(nb, csv, b, s, dt60, T, &ref.traj, sc->id, "xpbd", "gauss_seidel", refname, &xs_sub, dt60 / SUBSTEPS[i]);
    sim_destroy(s);
  }
  for (int i = 0; i < NITER; i++) {
    s = bar_pbd(b, 1, 1, ITERS[i], BAR_K, sc->c_ground, g, x0, &err);
    if (!s) break;
    measure(nb, csv, b, s, dt60, T, &ref.traj, sc->id, "xpbd", "gauss_seidel", refname, &xs_it, ITERS[i]);
    sim_destroy(s);
  }
  /* PBD against its own finest setting. */
  nb_progress("%s: PBD reference (256 sub-steps) and sweeps", sc->id);
  run_out_t pref;
  s = bar_pbd(b, 0, nb->quick ? 128 : 256, 1, BAR_K, sc->c_ground, g, x0, &err);
  sp = bar_spec(b, dt60, T);
  sp.reps = 1;
  if (s && run_sim(s, &sp, &pref, &err) == 0 && pref.stable) {
    sim_destroy(s);
    char prefname[64];
    snprintf(prefname, sizeof prefname, "pbd dt=1/60 %d substeps", nb->quick ? 128 : 256);
    for (int i = 0; i < NSUB; i++) {
      s = bar_pbd(b, 0, SUBSTEPS[i], 1, BAR_K, sc->c_ground, g, x0, &err);
      if (!s) break;
      measure(nb, csv, b, s, dt60, T, &pref.traj, sc->id, "pbd", "gauss_seidel", prefname, &pb_sub, dt60 / SUBSTEPS[i]);
      sim_destroy(s);
    }
    for (int i = 0; i < NITER; i++) {
      s = bar_pbd(b, 0, 1, ITERS[i], BAR_K, sc->c_ground, g, x0, &err);
      if (!s) break;
      measure(nb, csv, b, s, dt60, T, &pref.traj, sc->id, "pbd", "gauss_seidel", prefname, &pb_it, ITERS[i]);
      sim_destroy(s);
    }
    run_out_free(&pref);
  } else {
    sim_destroy(s);
    nb_progress("%s: PBD reference failed", sc->id);
  }
#endif

  /* Plot 1: work-precision. */
  char title[160], name[64];
  plot_t p;
  snprintf(title, sizeof title, "%s %s: work-precision (30x5x5 bar, %.1f s)", sc->id, sc->title, T);
  plot_init(&p, title, "wall time per simulated second (s, one core)", "e_x: max RMS position error / bbox diagonal",
            1, 1);
  p.pareto = 1;
  snprintf(p.empty_suffix, sizeof p.empty_suffix, " (all diverged)");
  for (int ki = 0; ki < NKINDS; ki++) plot_series(&p, &ms[ki], 1, 1);
  if (have_pbd) {
    plot_series(&p, &xs_sub, 1, 1);
    plot_series(&p, &xs_it, 1, 1);
    plot_series(&p, &pb_sub, 1, 0);
    plot_series(&p, &pb_it, 1, 0);
  }
  plot_note(&p, "Mass-spring: dt = 1/30 ... 1/%.0f s, 1 sub-step; XPBD/PBD: 60 Hz step. Missing points diverged.",
            1 / nb_dt(NDT - 1));
  plot_note(&p, "Reference: the same spring network by RK4 at 1/%.0f s; XPBD solves that network too. The Pareto "
                "front excludes PBD (other reference).",
            1 / dt_ref);
  if (!have_pbd) plot_note(&p, "PBD/XPBD not in this build.");
  if (inverted_note[0])
    plot_note(&p, "Runs ending with inverted tets (of %zu; sub-steps x iterations for XPBD/PBD): %s. An edge-only "
                  "network can rest inverted.",
              b->tm.ntets, inverted_note);
  snprintf(name, sizeof name, "plot1_work_precision_%s.png", sc->id);
  nb_plot(nb, &p, name);
  plot_free(&p);

  /* Plot 2: error vs step (sub-step length for XPBD/PBD). */
  snprintf(title, sizeof title, "%s %s: error vs time step", sc->id, sc->title);
  plot_init(&p, title, "time step dt, or sub-step dt/n for XPBD/PBD (s)", "e_x: max RMS position error / bbox diagonal",
            1, 1);
  snprintf(p.empty_suffix, sizeof p.empty_suffix, " (all diverged)");
  for (int ki = 0; ki < NKINDS; ki++) {
    series_t t = ms[ki];
    /* The asymptotic regime: the five smallest steps with a useful error. */
    double fx[MAXPTS], fy[MAXPTS];
    int nf = 0;
    for (int i = t.n - 1; i >= 0 && nf < 5; i--)
      if (t.err[i] > 1e-12 && t.err[i] < 0.05) fx[nf] = t.x[i], fy[nf] = t.err[i], nf++;
    double slope = plot_loglog_slope((size_t)nf, fx, fy, 0, 1, NULL);
    char lab[96];
    snprintf(lab, sizeof lab, "%s", t.label);
    if (isfinite(slope)) snprintf(t.label, sizeof t.label, "%.70s (slope %.2f)", lab, slope);
    plot_series(&p, &t, 0, 0);
  }
  if (have_pbd) {
    series_t t = xs_sub;
    double slope = plot_loglog_slope((size_t)t.n, t.x, t.err, 1e-12, 0.05, NULL);
    if (isfinite(slope)) snprintf(t.label, sizeof t.label, "XPBD, 1 iteration (slope %.2f)", slope);
    plot_series(&p, &t, 0, 0);
    t = pb_sub;
    snprintf(t.label, sizeof t.label, "PBD, 1 iteration (vs PBD 256 sub)");
    plot_series(&p, &t, 0, 0);
  }
  plot_note(&p,
            "Slopes: least squares over the five smallest steps with e_x in (1e-12, 0.05). Missing points diverged.");
  plot_note(&p, "Symplectic Euler and Verlet need dt < 2/omega_max = %.2g s here (omega_max by power iteration).",
            2 / bar_omega_max(b, BAR_K));
  if (inverted_note[0])
    plot_note(&p, "Runs ending with inverted tets (of %zu; sub-steps x iterations for XPBD/PBD): %s.", b->tm.ntets,
              inverted_note);
  snprintf(name, sizeof name, "plot2_error_vs_dt_%s.png", sc->id);
  nb_plot(nb, &p, name);
  plot_free(&p);

  /* Plot 5 (S4 only): equal cost, sub-steps against iterations. */
  if (have_pbd && sc->init == INIT_REST) {
    snprintf(title, sizeof title, "XPBD on the S4 bar at 60 Hz: sub-steps vs iterations at equal cost");
    plot_init(&p, title, "wall time per simulated second (s, one core)", "e_x: max RMS position error / bbox diagonal",
              1, 1);
    series_t a = xs_sub, c = xs_it;
    snprintf(a.label, sizeof a.label, "n sub-steps x 1 iteration");
    snprintf(c.label, sizeof c.label, "1 sub-step x n iterations");
    a.color = 0, a.marker = 0, c.color = 3, c.marker = 1;
    plot_series(&p, &a, 1, 0);
    double na[NSUB];
    for (int i = 0; i < a.n && i < NSUB; i++) na[i] = SUBSTEPS[i];
    plot_tag(&p.s[p.nseries - 1], na);
    plot_series(&p, &c, 1, 0);
    plot_tag(&p.s[p.nseries - 1], c.x); /* x holds the iteration count */
    plot_note(&p, "Point labels give n. n sub-steps x 1 iteration and 1 sub-step x n iterations both project every "
                  "constraint n times per step: equal n, equal work.");
    plot_note(&p, "Reference: the spring network by RK4 at 1/%.0f s (XPBD's converged limit).", 1 / dt_ref);
    nb_plot(nb, &p, "plot5_substeps_vs_iterations.png");
    plot_free(&p);
  }
  run_out_free(&ref);
  free(x0);
}

/* ---- static solutions of the spring network ------------------------------------------ */

/* Static sag of the spring network: Newton iterations, done as implicit
 * Euler steps of 10 s with the velocity reset (M/h^2 then regularises K by
 * 1e-2 relative at most), until the update is below 1e-12 of the bar. */
static double static_tip_sag(const bar_t *b, const double g[3], double load_x, double *u_quarter, double *u_3quarter) {
  verr_t err;
  mass_spring_t ms;
  ms_params_t p = {.mass = b->mass, .stiffness = BAR_K, .gravity = {g[0], g[1], g[2]}};
  if (mass_spring_create_tets(&ms, &b->tm, &p, &err)) return NAN;
  for (size_t i = 0; i < ms.n; i++)
    if (b->tm.x[3 * i] < 0.5 * b->h) ms.inv_mass[i] = 0;
  /* End load (N, along x) spread over the free end's nodes. */
  size_t nend = 0;
  for (size_t i = 0; i < ms.n; i++) nend += b->tm.x[3 * i] > ((double)b->nx - 1.5) * b->h;
  for (size_t i = 0; i < ms.n; i++)
    if (b->tm.x[3 * i] > ((double)b->nx - 1.5) * b->h) ms.f_ext[3 * i] = load_x / (double)nend;
  ms.definite_jacobian = 1;
  integrator_t it;
  if (integrator_init(&it, INT_IMPLICIT_EULER, ms.n, 1e-11, 20000, &err)) {
    mass_spring_destroy(&ms);
    return NAN;
  }
  double *prev = malloc(3 * ms.n * sizeof *prev);
  for (int k = 0; k < 200 && prev; k++) {
    memcpy(prev, ms.x, 3 * ms.n * sizeof *prev);
    integrator_substep(&it, &ms.fs, 10.0);
    memset(ms.v, 0, 3 * ms.n * sizeof(double));
    double d = 0;
    for (size_t c = 0; c < 3 * ms.n; c++) d = fmax(d, fabs(ms.x[c] - prev[c]));
    if (d < 1e-12 * b->diag) break;
  }
  free(prev);
  /* Mean axial displacement of the cross-sections at L/4 and 3L/4 (away
   * from the clamped and loaded ends). */
  size_t iq = (b->nx - 1) / 4, i3 = 3 * (b->nx - 1) / 4;
  double uq = 0, u3 = 0;
  for (size_t k = 0; k < b->nz; k++)
    for (size_t j = 0; j < b->ny; j++) {
      size_t a = iq + b->nx * (j + b->ny * k), c = i3 + b->nx * (j + b->ny * k);
      uq += ms.x[3 * a] - b->tm.x[3 * a];
      u3 += ms.x[3 * c] - b->tm.x[3 * c];
    }
  if (u_quarter) *u_quarter = uq / (double)(b->ny * b->nz);
  if (u_3quarter) *u_3quarter = u3 / (double)(b->ny * b->nz);
  /* Tip: mean displacement of the end face along gravity (or the load). */
  double tip = 0;
  double gn = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
  for (size_t i = 0; i < ms.n; i++) {
    if (!(b->tm.x[3 * i] > ((double)b->nx - 1.5) * b->h)) continue;
    if (gn > 0) for (int a = 0; a < 3; a++) tip += (ms.x[3 * i + a] - b->tm.x[3 * i + a]) * g[a] / gn;
    else tip += ms.x[3 * i] - b->tm.x[3 * i];
  }
  integrator_destroy(&it);
  mass_spring_destroy(&ms);
  return tip / (double)nend;
}

#ifdef NUMERICS_HAVE_PBD
/* ---- plot 4: tip sag vs iterations and dt -------------------------------------------- */

/* Damped dynamic run to rest; returns the tip sag averaged over the last
 * quarter second (the remaining oscillation averages out). */
static double damped_sag(const bar_t *b, int xpbd, int sub, int iters, double dt, double T, double *cost) {
  verr_t err;
  const double g[3] = {0, 0, -9.81};
  /* Ground damping near critical for the first bending mode (about 2 Hz). */
  double c = 0.9 * 2 * (2 * M_PI * 2.0) * (b->mass / (double)b->tm.nnodes);
  sim_t *s = bar_pbd(b, xpbd, sub, iters, BAR_K, c, g, NULL, &err);
  if (!s) return NAN;
  size_t n = (size_t)llround(T / dt), tail = (size_t)llround(0.25 / dt);
  double sum = 0;
  size_t cnt = 0;
  uint64_t t0 = vtime_mono_ns();
  int ok = 1;
  for (size_t k = 1; k <= n && ok; k++) {
    ok = s->step(s, dt) == 0;
    if (k + tail > n) {
      sum += b->tm.x[3 * b->tip + 2] - s->x[3 * b->tip + 2];
      cnt++;
    }
  }
  if (cost) *cost = (double)(vtime_mono_ns() - t0) * 1e-9 / T;
  sim_destroy(s);
  return ok && cnt ? sum / (double)cnt : NAN;
}

static void sag_study(nb_t *nb, const bar_t *b) {
  const double T = nb->quick ? 1.0 : 1.5;
  const double g[3] = {0, 0, -9.81};
  /* Iteration sweeps at the 60 Hz step and at 1/480 s (where Gauss-Seidel
   * gets close enough for the difference between the two to show). */
  const int NIDT = nb->quick ? 1 : 2;
  const double it_dt[2] = {1.0 / 60, 1.0 / 480};
  nb_progress("plot 4: damped tip sag, PBD and XPBD, vs iterations and vs dt (10 iterations)");
  double sag_static = static_tip_sag(b, g, 0, NULL, NULL);
  FILE *csv = nb_csv(nb, "plot4_sag.csv", "model,sweep,dt,substeps,iterations,tip_sag_m,static_sag_m,wall_s_per_sim_s");
  double it_x[NITER], it_sag[2][2][NITER];
  for (int di = 0; di < NIDT; di++)
    for (int m = 0; m < 2; m++)
      for (int i = 0; i < NITER; i++) {
        double cost = NAN;
        it_x[i] = ITERS[i];
        it_sag[di][m][i] = damped_sag(b, m, 1, ITERS[i], it_dt[di], T, &cost);
        if (csv)
          fprintf(csv, "%s,iterations,%.9g,1,%d,%.6e,%.6e,%.4e\n", m ? "xpbd" : "pbd", it_dt[di], ITERS[i],
                  it_sag[di][m][i], sag_static, cost);
      }
  const int ND = nb->quick ? 4 : 7;
  double dt_x[8], dt_sag[2][8];
  for (int m = 0; m < 2; m++)
    for (int d = 0; d < ND; d++) {
      double cost = NAN;
      dt_x[d] = nb_dt(d);
      dt_sag[m][d] = damped_sag(b, m, 1, 10, dt_x[d], T, &cost);
      if (csv)
        fprintf(csv, "%s,dt,%.9g,1,10,%.6e,%.6e,%.4e\n", m ? "xpbd" : "pbd", dt_x[d], dt_sag[m][d], sag_static, cost);
    }
  if (csv) fclose(csv);
  double line_x[2] = {1, 50}, line_y[2] = {sag_static, sag_static};
  plot_t p;
  plot_init(&p, "Plot 4a: bar tip sag vs iterations (1 sub-step, damped to rest)", "iterations per step",
            "tip sag (m)", 1, 1);
  for (int di = 0; di < NIDT; di++) {
    char lab[96];
    snprintf(lab, sizeof lab, "PBD (stiffness 1), dt 1/%.0f s", 1 / it_dt[di]);
    plot_add(&p, lab, NITER, it_x, it_sag[di][0], 3, di ? 2 : 0, di ? PLOT_LINE_SOLID : PLOT_LINE_DASHED);
    snprintf(lab, sizeof lab, "XPBD (compliance 1/k), dt 1/%.0f s", 1 / it_dt[di]);
    plot_add(&p, lab, NITER, it_x, it_sag[di][1], 0, di ? 3 : 1, di ? PLOT_LINE_SOLID : PLOT_LINE_DASHED);
  }
  plot_add(&p, "static sag of the spring network", 2, line_x, line_y, PLOT_BLACK, -1, PLOT_LINE_DASHED);
  plot_note(&p, "Bar %.2f m long, ground damping near critical for its 2 Hz bending mode; sag = tip z drop averaged "
                "over the last 0.25 s of %.1f s.",
            (double)(b->nx - 1) * b->h, T);
  plot_note(&p, "More iterations stiffen PBD without limit (towards the rigid bar); XPBD tends to the network's own "
                "sag (%.3f m) once dt is small enough for Gauss-Seidel to converge.",
            sag_static);
  nb_plot(nb, &p, "plot4_sag_vs_iterations.png");
  plot_free(&p);
  double lx2[2] = {dt_x[ND - 1], dt_x[0]};
  plot_init(&p, "Plot 4b: bar tip sag vs time step (10 iterations, 1 sub-step, damped to rest)", "time step dt (s)",
            "tip sag (m)", 1, 1);
  plot_add(&p, "PBD (stiffness 1)", (size_t)ND, dt_x, dt_sag[0], 3, 0, PLOT_LINE_SOLID);
  plot_add(&p, "XPBD (compliance 1/k)", (size_t)ND, dt_x, dt_sag[1], 0, 1, PLOT_LINE_SOLID);
  plot_add(&p, "static sag of the spring network", 2, lx2, line_y, PLOT_BLACK, -1, PLOT_LINE_DASHED);
  plot_note(&p, "PBD's effective stiffness grows as dt shrinks, so its sag drifts towards 0; XPBD's sag approaches "
                "the static answer of the model it solves.");
  nb_plot(nb, &p, "plot4_sag_vs_dt.png");
  plot_free(&p);
}
#endif

/* ---- model error: the spring network against beam theory -------------------------------- */

static void model_error(nb_t *nb, const bar_t *b) {
  nb_progress("bar model error: Young's modulus of the spring network, hanging bar and small-load cantilever");
  double L = (double)(b->nx - 1) * b->h, a = (double)(b->ny - 1) * b->h, A = a * a, I = a * a * a * a / 12;
  double rho = b->mass / (L * A);
  /* E from a uniaxial end load: u(x) is linear away from the ends. */
  const double F = 1.0, g0[3] = {0, 0, 0};
  double uq, u3;
  static_tip_sag(b, g0, F, &uq, &u3);
  double dx = (double)(3 * (b->nx - 1) / 4 - (b->nx - 1) / 4) * b->h;
  double E = F * dx / (A * (u3 - uq));
  /* Hanging bar: gravity along the axis, away from the clamp. */
  const double gh[3] = {9.81, 0, 0};
  double hang = static_tip_sag(b, gh, 0, NULL, NULL), hang_th = rho * 9.81 * L * L / (2 * E);
  /* Small-load cantilever (g / 1000: linear range) and the full load. */
  const double gs[3] = {0, 0, -9.81e-3}, gf[3] = {0, 0, -9.81};
  double cant = static_tip_sag(b, gs, 0, NULL, NULL), cant_full = static_tip_sag(b, gf, 0, NULL, NULL);
  double cant_th = rho * 9.81e-3 * A * L * L * L * L / (8 * E * I);
  FILE *csv = nb_csv(nb, "bar_model_error.csv", "quantity,simulated_m,theory_m,relative_error,note");
  if (csv) {
    fprintf(csv, "young_modulus_Pa,%.6e,,,from uniaxial end load %g N (L/4..3L/4)\n", E, F);
    fprintf(csv, "hanging_bar_tip,%.6e,%.6e,%.4e,rho g L^2 / 2E\n", hang, hang_th, hang / hang_th - 1);
    fprintf(csv, "cantilever_small_load_tip,%.6e,%.6e,%.4e,q L^4 / 8 E I at g/1000 (Euler-Bernoulli; shear and "
                 "lumped boundary masses not in theory)\n",
            cant, cant_th, cant / cant_th - 1);
    fprintf(csv, "cantilever_full_load_tip,%.6e,%.6e,%.4e,linear theory x 1000 (geometric nonlinearity)\n", cant_full,
            cant_th * 1000, cant_full / (cant_th * 1000) - 1);
    fclose(csv);
  }
  nb_progress("bar model: E = %.3g Pa; hanging-bar tip %.3e m vs %.3e m (%+.1f %%); cantilever (g/1000) %.3e m vs "
              "Euler-Bernoulli %.3e m (%+.1f %%); full-load sag %.3f m",
              E, hang, hang_th, 100 * (hang / hang_th - 1), cant, cant_th, 100 * (cant / cant_th - 1), cant_full);
  nb_row_t r;
  memset(&r, 0, sizeof r);
  snprintf(r.scene, sizeof r.scene, "S4m");
  snprintf(r.model, sizeof r.model, "mass_spring_tet");
  snprintf(r.integ, sizeof r.integ, "static");
  snprintf(r.setting, sizeof r.setting, "hanging bar vs rhogL2/2E");
  snprintf(r.metric, sizeof r.metric, "rel_model_err");
  r.err = r.err_end = fabs(hang / hang_th - 1);
  r.step_us = r.sim_ms = NAN;
  nb_add_row(nb, &r);
  snprintf(r.setting, sizeof r.setting, "cantilever vs EB, g/1000");
  r.err = r.err_end = fabs(cant / cant_th - 1);
  nb_add_row(nb, &r);
}

/* ---- the XPBD BarDemo setting (docs/numerics.md §7) --------------------------------------------- */

static void bardemo(nb_t *nb, const bar_t *b) {
#ifdef NUMERICS_HAVE_PBD
  /* dt 5 ms, 5 sub-steps x 1 iteration, gravity; timing only (the step
   * does not divide the 1/30 s sampling of the e_x runs). */
  verr_t err;
  const double g[3] = {0, 0, -9.81};
  sim_t *s = bar_pbd(b, 1, 5, 1, BAR_K, 0, g, NULL, &err);
  if (!s) return;
  run_spec_t sp = {.dt = 0.005, .T = nb->quick ? 0.5 : 2.0, .sample_dt = 0.1, .reps = 3, .blowup = 10 * b->diag};
  run_out_t o;
  if (run_sim(s, &sp, &o, &err) == 0) {
    nb_progress("XPBD BarDemo setting (750 nodes, %zu tets, %zu distance constraints, dt 5 ms, 5x1): %.3f ms per "
                "step median, p95 %.3f ms (target <= 0.6 ms)",
                b->tm.ntets, b->nedges, o.step_us_median * 1e-3, o.step_us_p95 * 1e-3);
    nb_target(nb, "XPBD BarDemo bar (30x5x5, %zu tets, %zu distance constraints; dt 5 ms, 5 sub-steps x 1 "
                  "iteration): %.3f ms per step median, p95 %.3f ms; target <= 0.6 ms",
              b->tm.ntets, b->nedges, o.step_us_median * 1e-3, o.step_us_p95 * 1e-3);
    nb_result(nb, "S4", "xpbd", "gauss_seidel", 0.005, 5, 1, "timing", NAN, NAN, &o);
    nb->rows[nb->nrows - 1].step_us = o.step_us_median;
    nb->rows[nb->nrows - 1].sim_ms = o.wall_per_sim_s * 1e3;
    snprintf(nb->rows[nb->nrows - 1].setting, sizeof nb->rows[0].setting, "BarDemo dt=5ms 5sub x 1it");
    run_out_free(&o);
  }
  sim_destroy(s);
#else
  (void)b;
  (void)nb;
#endif
}

/* docs/numerics.md §7 "cantilever bar at 60 Hz: e_x <= 5 % at the interactive
 * setting and <= 1 % at the accurate one, with the cost of each". */
static void cantilever_targets(nb_t *nb) {
  const nb_row_t *inter = NULL, *acc = NULL, *best60 = NULL;
  for (size_t i = 0; i < nb->nrows; i++) {
    const nb_row_t *r = &nb->rows[i];
    /* PBD's e_x is against PBD's own limit (the rigid bar), not the bar's
     * physics: it does not count for this target. */
    if (strcmp(r->scene, "S4") || strcmp(r->metric, "e_x") || !isfinite(r->err) || !strcmp(r->model, "pbd")) continue;
    int at60 = fabs(r->dt - 1.0 / 60) < 1e-9;
    if (at60 && (!best60 || r->err < best60->err)) best60 = r;
    if (at60 && r->err <= 0.05 && (!inter || r->sim_ms < inter->sim_ms)) inter = r;
    if (r->err <= 0.01 && (!acc || r->sim_ms < acc->sim_ms)) acc = r;
  }
  if (inter)
    nb_target(nb, "cantilever bar (S4), 60 Hz scene step, e_x <= 5 %%: cheapest is %s %s %s, e_x %.2g, %.3g ms per "
                  "simulated s",
              inter->model, inter->integ, inter->setting, inter->err, inter->sim_ms);
  else if (best60)
    nb_target(nb, "cantilever bar (S4), 60 Hz scene step: no mass-spring or XPBD setting reaches e_x <= 5 %%; best is "
                  "%s %s %s at %.2g",
              best60->model, best60->integ, best60->setting, best60->err);
  if (acc)
    nb_target(nb, "cantilever bar (S4), e_x <= 1 %% (any step): cheapest is %s %s %s, e_x %.2g, %.3g ms per "
                  "simulated s",
              acc->model, acc->integ, acc->setting, acc->err, acc->sim_ms);
}

void scene_bar(nb_t *nb) {
  verr_t err;
  bar_t b;
  if (bar_init(&b, 30, 5, 5, BAR_H, &err)) {
    nb_skip(nb, "bar scenes: %s", err.msg);
    return;
  }
  nb_progress("bar: %zu nodes, %zu tets, %zu edges, %.2f kg, diagonal %.3f m", b.tm.nnodes, b.tm.ntets, b.nedges, b.mass,
              b.diag);
  FILE *csv = nb_csv(nb, "bar_scenes.csv", CSV_HEADER);
  /* S4 is undamped. S5 and S6 get ground damping of 0.35 N s/m per node
   * (damping ratio about 0.25 on the first axial mode): undamped, the
   * released spring network recoils through itself (hundreds of inverted
   * tetrahedra, no volume term resists) and its trajectory stops being
   * smooth, so no reference converges (halving the RK4 step changed e_x by
   * 0.3). */
  static const bar_scene_t SCENES[] = {
      {"S4", "cantilever under gravity", 1, INIT_REST, 1.0, 0.4, 0, 10},
      {"S6", "uniaxial stretch to 1.5x, released", 0, INIT_STRETCH, 0.5, 0.2, 0.35, 11},
      {"S5", "360 degree twist, released", 0, INIT_TWIST, 0.5, 0.2, 0.35, 11}};
  int nsc = nb->quick ? 2 : 3;
  if (nb->quick) nb_skip(nb, "S5 twist: left out of --quick (runs in the full benchmark)");
  for (int i = 0; i < nsc; i++) {
    bar_scene(nb, &b, &SCENES[i], csv);
    if (i == 0) cantilever_targets(nb);
  }
  if (csv) fclose(csv);
#ifdef NUMERICS_HAVE_PBD
  sag_study(nb, &b);
#else
  nb_skip(nb, "S4 PBD/XPBD, plots 4 and 5: pbd.c is not in viscera_sim in this build");
#endif
  model_error(nb, &b);
  bardemo(nb, &b);
  nb_skip(nb, "S4 at 60x10x10 cells: accuracy sweep left out for time (its step cost is in plot 7)");
  bar_free(&b);
}
