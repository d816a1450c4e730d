/* SPDX-License-Identifier: Apache-2.0 */
/* docs/numerics.md §5 case 1: step-limit sweep, edge stiffness k = 1 .. 1e6 on a
 * 6 x 6 cloth (36 nodes, no damping).
 *
 *  - symplectic Euler: the largest stable dt found by bisection (a run of
 *    5,000 steps from a small random displacement that stays below 1000x
 *    its start) against the bound the model reports, 2/omega_max with
 *    omega_max by power iteration: bound / dt_max must lie in 0.85 .. 1.0
 *    (never above the real limit, never needlessly small);
 *  - undamped explicit Euler: refused by the model (unstable at every step)
 *    and, forced to run at a tenth of the symplectic limit, its energy grows;
 *  - implicit Euler at 33 ms (30 Hz) for every k: no rollback, all finite,
 *    energy never above its start. */
#include "stab_util.h"

static const double AMP = 1e-6; /* m, start displacement (linear regime) */

static void displace(model_t *m) {
  stab_seed = 99;
  for (size_t c = 0; c < 3 * m->nnodes; c++) {
    m->x[c] = m->x_rest[c] + AMP * stab_rand();
    m->v[c] = 0;
  }
  model_note_outside_write(m);
}

static double max_offset(const model_t *m) {
  double d = 0;
  for (size_t c = 0; c < 3 * m->nnodes; c++) d = fmax(d, fabs(m->x[c] - m->x_rest[c]));
  return d;
}

static int stays_bounded(model_t *m, double dt) {
  displace(m);
  double start = max_offset(m);
  for (int s = 0; s < 5000; s++)
    if (m->ops->step(m, dt) < 0 || max_offset(m) > 1e3 * start) return 0;
  return 1;
}

/* Regional sleeping off (solver.region_force 0): the 1 um start displacement
 * of the soft cloths is below its wake force, so it would hold the cloth
 * still at any step; this sweep measures the scheme itself. */
static scene_organ_t cloth_organ(const char *integrator, int substeps, double k) {
  char yaml[512];
  snprintf(yaml, sizeof yaml,
           "    integrator: %s\n    solver: {substeps: %d, region_force: 0}\n"
           "    material: {mass: 0.036, stiffness: %g, damping: 0, home_stiffness: 1, home_damping: 0}\n",
           integrator, substeps, k);
  return stab_organ(yaml);
}

int main(void) {
  mesh_t cloth;
  stab_grid(&cloth, 6, 0.01);
  printf("%10s %12s %12s %8s %14s %14s\n", "k N/m", "bound ms", "dt_max ms", "ratio", "explicit E/E0", "implicit E/E0");
  for (double k = 1; k <= 1e6 * 1.0001; k *= 10) {
    verr_t err;

    /* Symplectic Euler: reported bound against the measured limit. */
    scene_organ_t c = cloth_organ("symplectic_euler", 1, k);
    model_t *m = stab_model(&c, &cloth, NULL, 1e-3, &err);
    CHECK(m != NULL);
    if (!m) return check_report("stab_step_limit");
    double bound = m->stable_dt, lo = 0.5 * bound, hi = 2 * bound;
    CHECK(stays_bounded(m, lo) && !stays_bounded(m, hi));
    for (int i = 0; i < 14; i++) { /* 4x range / 2^14: 2.4e-4 relative */
      double mid = 0.5 * (lo + hi);
      if (stays_bounded(m, mid))
        lo = mid;
      else
        hi = mid;
    }
    double ratio = bound / lo;
    CHECK(ratio >= 0.85 && ratio <= 1.0);
    model_destroy(m);

    /* Undamped explicit Euler: refused when sub-steps are automatic ... */
    c = cloth_organ("explicit_euler", 0, k);
    CHECK(stab_model(&c, &cloth, NULL, 1e-3, &err) == NULL && strstr(err.msg, "unstable at every step size"));
    /* ... and its energy grows even at a tenth of the symplectic limit. */
    c = cloth_organ("explicit_euler", 1, k);
    m = stab_model(&c, &cloth, NULL, 1e-3, &err);
    CHECK(m != NULL && m->stable_dt == 0);
    if (!m) return check_report("stab_step_limit");
    displace(m);
    double e0 = m->ops->energy(m), ee = e0;
    for (int s = 0; s < 2000 && m->rollbacks == 0; s++) {
      m->ops->step(m, 0.1 * bound);
      ee = m->ops->energy(m);
    }
    CHECK(ee > 1.5 * e0 || m->rollbacks > 0);
    model_destroy(m);

    /* Implicit Euler at 30 Hz. */
    c = cloth_organ("implicit_euler", 0, k);
    m = stab_model(&c, &cloth, NULL, 1.0 / 30, &err);
    CHECK(m != NULL && m->substeps == 1 && isinf(m->stable_dt));
    if (!m) return check_report("stab_step_limit");
    displace(m);
    double i0 = m->ops->energy(m), imax = 0;
    int ok = 1;
    for (int s = 0; s < 300; s++) {
      ok = ok && m->ops->step(m, 1.0 / 30) == 0;
      imax = fmax(imax, m->ops->energy(m) / i0);
    }
    CHECK(ok && m->rollbacks == 0 && stab_finite(m->x, 3 * m->nnodes) && stab_finite(m->v, 3 * m->nnodes));
    CHECK(imax <= 1 + 1e-9);
    CHECK(max_offset(m) <= 1.5 * AMP);
    printf("%10g %12.5g %12.5g %8.4f %14.3g %14.6f\n", k, bound * 1e3, lo * 1e3, ratio, ee / e0, imax);
    model_destroy(m);
  }
  mesh_free(&cloth);
  return check_report("stab_step_limit");
}
