/* SPDX-License-Identifier: Apache-2.0 */
/* Plot 3: the largest stable time step against stiffness, measured by
 * bisection, beside the bound 2/omega_max with omega_max from power
 * iteration (docs/numerics.md §4 plot 3, §5 case 1, §6).
 *
 * System: the product's mass_spring_tet force system on a small bar
 * (10 x 3 x 3 nodes, 2 cm spacing, 0.29 kg, one end fixed), undamped, no
 * gravity, edge stiffness k = 1 ... 1e6 N/m. A run starts from the rest
 * state plus a fixed pseudo-random displacement of 1e-6 of the spacing (the
 * linear regime) and counts as unstable when its energy exceeds 1e4 times
 * the initial energy (or turns non-finite) within N steps. An unstable mode
 * just past the bound grows by 1 + O(sqrt(eps)) per step, so N = 2000
 * steps resolve the bound to well under 1 %. Explicit Euler gains energy at
 * every step size on an undamped system (factor 1 + h^2 omega^2 per step):
 * what it is given here is the step below which that growth stays under 1e4
 * in N steps, labelled as such. Implicit Euler and XPBD are tried at the
 * 0.1 s cap (and at 1/30 s). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bar.h"
#include "physics/mass_spring.h"
#include "plot/plot.h"

#define NSTIFF 7
#define CAP 0.1

typedef struct probe_ctx {
  const bar_t *b;
  double k;
  int xpbd; /* 0: mass-spring with `kind`; 1: XPBD */
  integrator_kind_t kind;
  int nsteps;
} probe_ctx_t;

static void perturbation(const bar_t *b, double *x) {
  memcpy(x, b->tm.x, 3 * b->tm.nnodes * sizeof *x);
  uint64_t r = 0x2545F4914F6CDD1Dull;
  for (size_t c = 0; c < 3 * b->tm.nnodes; c++) {
    r ^= r << 13, r ^= r >> 7, r ^= r << 17;
    x[c] += 1e-6 * b->h * ((double)(r >> 11) / 9007199254740992.0 - 0.5);
  }
}

/* 1 when the run stays bounded. */
static int stable_at(const probe_ctx_t *pc, double h) {
  verr_t err;
  const double g[3] = {0, 0, 0};
  double *x0 = malloc(3 * pc->b->tm.nnodes * sizeof *x0);
  if (!x0) return 0;
  perturbation(pc->b, x0);
  sim_t *s = NULL;
#ifdef NUMERICS_HAVE_PBD
  if (pc->xpbd) s = bar_pbd(pc->b, 1, 1, 10, pc->k, 0, g, x0, &err);
  else
#endif
    s = bar_mass_spring(pc->b, pc->kind, 1, pc->k, 0, g, x0, 1e-6, &err);
  free(x0);
  if (!s) return 0;
  double E0 = s->energy(s);
  int ok = isfinite(E0) && E0 > 0;
  for (int k = 1; k <= pc->nsteps && ok; k++) {
    if (s->step(s, h)) ok = 0;
    else if (k % 25 == 0 || k == pc->nsteps) {
      double E = s->energy(s);
      if (!(E <= 1e4 * E0)) ok = 0;
    }
  }
  sim_destroy(s);
  return ok;
}

/* Largest stable step by bisection in log h, bracketed around `guess`.
 * Returns CAP when stable there, 0 when unstable even at guess / 1e4. */
static double bisect(const probe_ctx_t *pc, double guess, int rounds) {
  double lo = guess * 0.5, hi = guess * 2;
  while (!stable_at(pc, lo)) {
    hi = lo;
    lo *= 0.1;
    if (lo < guess * 1e-4) return 0;
  }
  while (stable_at(pc, hi)) {
    lo = hi;
    hi *= 2;
    if (hi > CAP) {
      if (stable_at(pc, CAP)) return CAP;
      hi = CAP;
      break;
    }
  }
  for (int i = 0; i < rounds; i++) {
    double mid = sqrt(lo * hi);
    if (stable_at(pc, mid)) lo = mid;
    else hi = mid;
  }
  return lo;
}

/* Largest eigenvalue of M^-1 K at rest over the free nodes, by plain power
 * iteration on the force system's stiffness_mul (independent of the
 * model's own bound, which the CSV reports beside it). */
static double power_lambda(force_system_t *fs, const double *x, int iters) {
  size_t n3 = 3 * fs->n;
  double *y = malloc(n3 * sizeof *y), *z = malloc(n3 * sizeof *z);
  if (!y || !z) {
    free(y);
    free(z);
    return NAN;
  }
  uint64_t r = 88172645463325252ull;
  for (size_t c = 0; c < n3; c++) {
    r ^= r << 13, r ^= r >> 7, r ^= r << 17;
    y[c] = fs->inv_mass[c / 3] > 0 ? (double)(r >> 11) / 9007199254740992.0 - 0.5 : 0;
  }
  double lam = NAN;
  for (int it = 0; it < iters; it++) {
    double ny = 0;
    for (size_t c = 0; c < n3; c++) ny += y[c] * y[c];
    ny = sqrt(ny);
    if (!(ny > 0)) break;
    for (size_t c = 0; c < n3; c++) y[c] /= ny;
    fs->stiffness_mul(fs, x, 1, 0, y, z);
    double nz = 0;
    for (size_t c = 0; c < n3; c++) {
      z[c] *= fs->inv_mass[c / 3];
      nz += z[c] * z[c];
    }
    lam = sqrt(nz);
    memcpy(y, z, n3 * sizeof *y);
  }
  free(y);
  free(z);
  return lam;
}

void scene_stability(nb_t *nb) {
  verr_t err;
  bar_t b;
  if (bar_init(&b, 10, 3, 3, 0.02, &err)) {
    nb_skip(nb, "plot 3: %s", err.msg);
    return;
  }
  const int NSTEPS = nb->quick ? 1000 : 2000, ROUNDS = nb->quick ? 8 : 14;
  nb_progress("plot 3: largest stable dt vs stiffness (10x3x3 bar, k = 1..1e6 N/m, %d steps per trial)", NSTEPS);
  static const integrator_kind_t EXPL[] = {INT_EXPLICIT_EULER, INT_SYMPLECTIC_EULER, INT_VERLET, INT_RK4};
  double ks[NSTIFF], bound[NSTIFF], bound_rk4[NSTIFF], dtmax[4][NSTIFF], imp[NSTIFF], xp[NSTIFF];
  FILE *csv = nb_csv(nb, "plot3_stable_dt.csv",
                     "k_N_per_m,omega_max_power_iteration,omega_max_model_bound,two_over_omega_s,scheme,dt_max_s,"
                     "ratio_to_two_over_omega,note");
  for (int i = 0; i < NSTIFF; i++) {
    double k = pow(10, i);
    ks[i] = k;
    mass_spring_t ms;
    ms_params_t p = {.mass = b.mass, .stiffness = k};
    double omega = NAN, omega_model = NAN;
    if (mass_spring_create_tets(&ms, &b.tm, &p, &err) == 0) {
      for (size_t j = 0; j < ms.n; j++)
        if (b.tm.x[3 * j] < 0.5 * b.h) ms.inv_mass[j] = 0;
      omega = sqrt(power_lambda(&ms.fs, ms.x_rest, 3000));
      double lk, lc;
      if (mass_spring_eigen_bounds(&ms, 0, &lk, &lc) == 0) omega_model = sqrt(lk);
      mass_spring_destroy(&ms);
    }
    bound[i] = 2 / omega;
    bound_rk4[i] = 2 * M_SQRT2 / omega; /* RK4 on the imaginary axis: |h omega| <= 2 sqrt 2 */
    for (int e = 0; e < 4; e++) {
      probe_ctx_t pc = {.b = &b, .k = k, .kind = EXPL[e], .nsteps = NSTEPS};
      dtmax[e][i] = bisect(&pc, bound[i], ROUNDS);
      if (csv)
        fprintf(csv, "%.0f,%.6e,%.6e,%.6e,%s,%.6e,%.4f,%s\n", k, omega, omega_model, bound[i], integrator_name(EXPL[e]),
                dtmax[e][i], dtmax[e][i] / bound[i],
                EXPL[e] == INT_EXPLICIT_EULER ? "energy grows at every dt; this is where growth stays < 1e4 in N steps"
                                              : "");
    }
    /* Implicit Euler and XPBD at the cap and at the 30 Hz step. */
    probe_ctx_t pi = {.b = &b, .k = k, .kind = INT_IMPLICIT_EULER, .nsteps = 300};
    int imp_cap = stable_at(&pi, CAP), imp_30 = stable_at(&pi, 1.0 / 30);
    imp[i] = imp_cap ? CAP : NAN;
    int xp_cap = 0, xp_30 = 0;
#ifdef NUMERICS_HAVE_PBD
    probe_ctx_t px = {.b = &b, .k = k, .xpbd = 1, .nsteps = 300};
    xp_cap = stable_at(&px, CAP);
    xp_30 = stable_at(&px, 1.0 / 30);
#endif
    xp[i] = xp_cap ? CAP : NAN;
    if (csv) {
      fprintf(csv, "%.0f,%.6e,%.6e,%.6e,implicit_euler,%s,,stable at 0.1 s: %d; at 1/30 s: %d\n", k, omega, omega_model,
              bound[i], imp_cap ? ">=0.1" : "<0.1", imp_cap, imp_30);
      fprintf(csv, "%.0f,%.6e,%.6e,%.6e,xpbd_10it,%s,,stable at 0.1 s: %d; at 1/30 s: %d\n", k, omega, omega_model,
              bound[i], xp_cap ? ">=0.1" : "<0.1", xp_cap, xp_30);
    }
    nb_progress("plot 3: k = %.0e: 2/omega = %.3g s; symplectic %.3g (x%.3f), Verlet %.3g (x%.3f), RK4 %.3g (x%.3f), "
                "explicit Euler %.3g; implicit stable at 0.1 s / 33 ms: %d/%d, XPBD: %d/%d",
                k, bound[i], dtmax[1][i], dtmax[1][i] / bound[i], dtmax[2][i], dtmax[2][i] / bound[i], dtmax[3][i],
                dtmax[3][i] / bound[i], dtmax[0][i], imp_cap, imp_30, xp_cap, xp_30);
  }
  if (csv) fclose(csv);
  plot_t p;
  plot_init(&p, "Plot 3: largest stable time step vs spring stiffness (10x3x3 mass-spring bar)",
            "edge stiffness k (N/m)", "largest stable dt (s)", 1, 1);
  plot_add(&p, "2 / omega_max (power iteration)", NSTIFF, ks, bound, PLOT_BLACK, -1, PLOT_LINE_DASHED);
  plot_add(&p, "2 sqrt(2) / omega_max (RK4 bound)", NSTIFF, ks, bound_rk4, PLOT_GREY, -1, PLOT_LINE_DOTTED);
  static const char *LAB[4] = {"explicit Euler (growth < 1e4 in N steps)", "symplectic Euler", "Verlet", "RK4"};
  /* Symplectic Euler and Verlet share their bound: draw them a little left
   * and right of k so both stay visible. */
  double kx[4][NSTIFF];
  for (int i = 0; i < NSTIFF; i++) {
    kx[0][i] = kx[3][i] = ks[i];
    kx[1][i] = ks[i] / 1.15;
    kx[2][i] = ks[i] * 1.15;
  }
  for (int e = 0; e < 4; e++) plot_add(&p, LAB[e], NSTIFF, kx[e], dtmax[e], e, e, PLOT_LINE_NONE);
  /* Both sit at the cap: offset sideways so neither hides the other. */
  double kl[NSTIFF], kr[NSTIFF];
  for (int i = 0; i < NSTIFF; i++) kl[i] = ks[i] / 1.35, kr[i] = ks[i] * 1.35;
  plot_add(&p, "implicit Euler: stable at the 0.1 s cap", NSTIFF, kl, imp, 4, 4, PLOT_LINE_NONE);
#ifdef NUMERICS_HAVE_PBD
  plot_add(&p, "XPBD (10 it.): stable at the 0.1 s cap", NSTIFF, kr, xp, 5, 2, PLOT_LINE_NONE);
#endif
  plot_note(&p, "Bisection on dt: unstable when the energy passes 1e4 x E0 within %d steps from a 1e-6 h perturbation.",
            NSTEPS);
  plot_note(&p, "Undamped explicit Euler is unstable at every dt (energy x (1 + h^2 omega^2) per step).");
  plot_note(&p, "Points at 0.1 s: stable at the largest step tried (and at 1/30 s). Coinciding points are drawn "
                "slightly left and right of their k.");
  nb_plot(nb, &p, "plot3_stable_dt_vs_stiffness.png");
  plot_free(&p);
  bar_free(&b);
}
