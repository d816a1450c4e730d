/* SPDX-License-Identifier: Apache-2.0 */
/* Integrators on linear springs, where the exact answer is known:
 * convergence order fitted from the error-vs-dt slope (explicit and
 * symplectic Euler ~1, Verlet ~2, RK4 ~4, implicit Euler ~1), the implicit
 * step against the closed-form backward Euler update, the stability bounds
 * of integrator_stable_dt against what the schemes actually do just below
 * and just above them, fixed-node masking, and the hook call per sub-step. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "physics/integrator.h"

/* n independent nodes, each tied to the origin by a spring k and a damper c
 * (x'' = -k/m x - c/m x' per coordinate); node j optionally also tied to
 * node j-1 by a spring kc (a chain, for masking tests). */
typedef struct spring_sys {
  force_system_t fs;
  double k, c, kc;
  double x[12], v[12], mass[4], inv_mass[4];
  int pre_calls;
  double ext_k, f_ext[12]; /* a spring to the origin applied from pre_substep, like a contact */
} spring_sys_t;

static void ss_forces(force_system_t *s, const double *x, const double *v, double *f) {
  spring_sys_t *p = (spring_sys_t *)s;
  for (size_t c = 0; c < 3 * s->n; c++) f[c] = -p->k * x[c] - p->c * v[c] + p->f_ext[c];
  for (size_t j = 1; j < s->n; j++)
    for (int k = 0; k < 3; k++) {
      double d = p->kc * (x[3 * j + k] - x[3 * (j - 1) + k]);
      f[3 * j + k] -= d;
      f[3 * (j - 1) + k] += d;
    }
}

static void ss_stiffness_mul(force_system_t *s, const double *x, double a, double b, const double *y, double *out) {
  spring_sys_t *p = (spring_sys_t *)s;
  for (size_t c = 0; c < 3 * s->n; c++) out[c] = (a * p->k + b * p->c) * y[c];
  for (size_t j = 1; j < s->n; j++)
    for (int k = 0; k < 3; k++) {
      double d = a * p->kc * (y[3 * j + k] - y[3 * (j - 1) + k]);
      out[3 * j + k] += d;
      out[3 * (j - 1) + k] -= d;
    }
}

static void ss_pre(force_system_t *s) {
  spring_sys_t *p = (spring_sys_t *)s;
  p->pre_calls++;
  for (size_t c = 0; c < 3 * s->n; c++) p->f_ext[c] = -p->ext_k * s->x[c];
}

static void ss_init(spring_sys_t *p, size_t n, double m, double k, double c) {
  memset(p, 0, sizeof *p);
  p->k = k;
  p->c = c;
  for (size_t i = 0; i < n; i++) {
    p->mass[i] = m;
    p->inv_mass[i] = 1 / m;
  }
  p->fs = (force_system_t){.n = n,
                           .x = p->x,
                           .v = p->v,
                           .mass = p->mass,
                           .inv_mass = p->inv_mass,
                           .forces = ss_forces,
                           .stiffness_mul = ss_stiffness_mul,
                           .pre_substep = ss_pre};
}

static const double X0[3] = {1.0, 0.5, -0.3}, V0[3] = {0.0, 1.0, 0.2};

/* Error of the state after time T = 1.3 (omega = 2 pi) in `steps` steps,
 * against the exact solution. T is not a whole number of periods: at
 * exactly one period symplectic Euler's first-order error cancels and it
 * would look second order. */
static double run_error(integrator_kind_t kind, int steps) {
  const double w = 2 * M_PI, T = 1.3;
  spring_sys_t p;
  ss_init(&p, 1, 1.0, w * w, 0);
  memcpy(p.x, X0, sizeof X0);
  memcpy(p.v, V0, sizeof V0);
  integrator_t it;
  verr_t err;
  if (integrator_init(&it, kind, 1, 1e-13, 50, &err)) return NAN;
  double h = T / steps;
  for (int s = 0; s < steps; s++) integrator_substep(&it, &p.fs, h);
  integrator_destroy(&it);
  double e2 = 0;
  for (int k = 0; k < 3; k++) {
    double xe = X0[k] * cos(w * T) + V0[k] / w * sin(w * T);
    double ve = -X0[k] * w * sin(w * T) + V0[k] * cos(w * T);
    e2 += (p.x[k] - xe) * (p.x[k] - xe) + (p.v[k] - ve) * (p.v[k] - ve) / (w * w);
  }
  return sqrt(e2);
}

/* Least-squares slope of log(error) against log(dt) over steps, 2 steps, ... */
static double fitted_order(integrator_kind_t kind, int steps0, int levels) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int l = 0; l < levels; l++) {
    int steps = steps0 << l;
    double lx = log(1.0 / steps), ly = log(run_error(kind, steps));
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
  }
  return (levels * sxy - sx * sy) / (levels * sxx - sx * sx);
}

static void test_orders(void) {
  double o_ee = fitted_order(INT_EXPLICIT_EULER, 1024, 5);
  double o_se = fitted_order(INT_SYMPLECTIC_EULER, 1024, 5);
  double o_vv = fitted_order(INT_VERLET, 64, 5);
  double o_rk = fitted_order(INT_RK4, 32, 5);
  double o_ie = fitted_order(INT_IMPLICIT_EULER, 1024, 5);
  printf("fitted orders: explicit_euler %.3f, symplectic_euler %.3f, verlet %.3f, rk4 %.3f, implicit_euler %.3f\n",
         o_ee, o_se, o_vv, o_rk, o_ie);
  CHECK_NEAR(o_ee, 1, 0.15);
  CHECK_NEAR(o_se, 1, 0.15);
  CHECK_NEAR(o_vv, 2, 0.15);
  CHECK_NEAR(o_rk, 4, 0.3);
  CHECK_NEAR(o_ie, 1, 0.15);
}

/* Implicit Euler on a linear damped spring is one exact backward Euler
 * step: (m + h c + h^2 k) dv = h (-k x - c v - h k v). */
static void test_implicit_exact(void) {
  const double m = 0.2, k = 500, c = 0.7, h = 0.05;
  spring_sys_t p;
  ss_init(&p, 1, m, k, c);
  memcpy(p.x, X0, sizeof X0);
  memcpy(p.v, V0, sizeof V0);
  integrator_t it;
  verr_t err;
  CHECK(integrator_init(&it, INT_IMPLICIT_EULER, 1, 1e-12, 20, &err) == 0);
  integrator_substep(&it, &p.fs, h);
  for (int d = 0; d < 3; d++) {
    double dv = h * (-k * X0[d] - c * V0[d] - h * k * V0[d]) / (m + h * c + h * h * k);
    double v = V0[d] + dv, x = X0[d] + h * v;
    CHECK_NEAR(p.v[d], v, 1e-12 * (1 + fabs(v)));
    CHECK_NEAR(p.x[d], x, 1e-12 * (1 + fabs(x)));
  }
  CHECK(it.last_cg_iterations >= 1 && it.last_cg_residual <= 1e-12);
  CHECK(p.pre_calls == 1);
  /* Unconditionally stable: omega h = 100 decays instead of exploding. */
  for (int s = 0; s < 100; s++) integrator_substep(&it, &p.fs, 100 / sqrt(k / m));
  CHECK(fabs(p.x[0]) < 1e-3 && fabs(p.x[1]) < 1e-3 && fabs(p.x[2]) < 1e-3);
  integrator_destroy(&it);
  /* CG tolerance and iteration cap are validated. */
  CHECK(integrator_init(&it, INT_IMPLICIT_EULER, 1, 0, 20, &err) == -1);
  CHECK(integrator_init(&it, INT_IMPLICIT_EULER, 1, 1e-3, 0, &err) == -1);
}

/* Growth over `steps` steps of h from x = 1, v = 0 (one coordinate): the
 * largest |x| in the last quarter over the largest in the first. Near a
 * bound the amplitude may swing far above 1 (symplectic Euler's invariant
 * ellipse stretches as h omega -> 2; critical damping has a transient
 * peak), so bounded means "not growing", not "small". */
static double growth(integrator_kind_t kind, double lk, double lc, double h, int steps) {
  spring_sys_t p;
  ss_init(&p, 1, 1.0, lk, lc);
  p.x[0] = 1;
  integrator_t it;
  verr_t err;
  if (integrator_init(&it, kind, 1, 1e-10, 50, &err)) return NAN;
  double early = 0, late = 0;
  for (int s = 0; s < steps; s++) {
    integrator_substep(&it, &p.fs, h);
    double a = fabs(p.x[0]);
    if (!(a < 1e250)) { /* overflowing: unbounded growth */
      late = INFINITY;
      break;
    }
    if (s < steps / 4) early = fmax(early, a);
    if (s >= steps - steps / 4) late = fmax(late, a);
  }
  integrator_destroy(&it);
  return late / early;
}

static void test_stable_dt(void) {
  const double w = 50;
  CHECK_NEAR(integrator_stable_dt(INT_SYMPLECTIC_EULER, w * w, 0), 2 / w, 1e-12);
  CHECK_NEAR(integrator_stable_dt(INT_VERLET, w * w, 0), 2 / w, 1e-9);
  CHECK_NEAR(integrator_stable_dt(INT_RK4, w * w, 0), 2 * sqrt(2) / w, 1e-9);
  CHECK(integrator_stable_dt(INT_EXPLICIT_EULER, w * w, 0) == 0); /* undamped: unstable at every h */
  CHECK_NEAR(integrator_stable_dt(INT_EXPLICIT_EULER, w * w, 10), 10 / (w * w), 1e-15);
  CHECK(isinf(integrator_stable_dt(INT_IMPLICIT_EULER, w * w, 10)));
  CHECK(isinf(integrator_stable_dt(INT_SYMPLECTIC_EULER, 0, 0)));
  CHECK_NEAR(integrator_stable_dt(INT_SYMPLECTIC_EULER, 0, 4), 0.5, 1e-15);
  /* RK4 on a purely damped mode: the real-axis limit 2.785 / rate. */
  CHECK_NEAR(integrator_stable_dt(INT_RK4, 0, 100) * 100, 2.785, 1e-3);

  /* Each bound against the scheme itself: bounded just below, growing just
   * above, from undamped to over-damped. */
  static const double damping[] = {0, 5, 40, 100, 300};
  for (int kind = 0; kind < INT_IMPLICIT_EULER; kind++)
    for (size_t d = 0; d < sizeof damping / sizeof damping[0]; d++) {
      double lk = w * w, lc = damping[d], bound = integrator_stable_dt((integrator_kind_t)kind, lk, lc);
      if (bound == 0) continue; /* undamped explicit Euler, checked above */
      double below = growth((integrator_kind_t)kind, lk, lc, 0.99 * bound, 20000);
      double above = growth((integrator_kind_t)kind, lk, lc, 1.02 * bound, 20000);
      if (!(below <= 1.01) || !(above > 2))
        fprintf(stderr, "  %s lk %g lc %g bound %g: growth below %g, above %g\n", integrator_name(kind), lk, lc, bound,
                below, above);
      CHECK(below <= 1.01);
      CHECK(above > 2);
    }
}

/* A chain of 3 nodes with the first fixed: it never moves; the others do.
 * pre_substep runs before every force evaluation: once per sub-step for
 * the Euler schemes, twice for Verlet, four times for RK4. */
static void test_fixed_nodes(void) {
  static const int evals[INT_COUNT] = {1, 1, 2, 4, 1, 1};
  for (int kind = 0; kind < INT_COUNT; kind++) {
    spring_sys_t p;
    ss_init(&p, 3, 0.1, 10, 0.1);
    p.kc = 40;
    p.inv_mass[0] = 0;
    for (int c = 0; c < 9; c++) p.x[c] = 0.01 * (c + 1);
    double fixed[3] = {p.x[0], p.x[1], p.x[2]}, moving = p.x[6];
    integrator_t it;
    verr_t err;
    CHECK(integrator_init(&it, (integrator_kind_t)kind, 3, 1e-8, 100, &err) == 0);
    for (int s = 0; s < 50; s++) integrator_substep(&it, &p.fs, 1e-3);
    CHECK(p.x[0] == fixed[0] && p.x[1] == fixed[1] && p.x[2] == fixed[2]);
    CHECK(p.v[0] == 0 && p.v[1] == 0 && p.v[2] == 0);
    CHECK(p.x[6] != moving);
    CHECK(p.pre_calls == 50 * evals[kind]);
    integrator_destroy(&it);
  }
}

/* A spring applied from pre_substep at the current state (as the contact
 * hook does) gives the same trajectory as the same spring inside forces():
 * every explicit scheme evaluates it where it evaluates the other forces. */
static void test_external_spring(void) {
  for (int kind = 0; kind < INT_IMPLICIT_EULER; kind++) {
    spring_sys_t a, b;
    ss_init(&a, 1, 0.01, 30, 0.02);
    ss_init(&b, 1, 0.01, 10, 0.02);
    b.ext_k = 20;
    memcpy(a.x, X0, sizeof X0);
    memcpy(b.x, X0, sizeof X0);
    integrator_t ia, ib;
    verr_t err;
    CHECK(integrator_init(&ia, (integrator_kind_t)kind, 1, 1e-8, 10, &err) == 0);
    CHECK(integrator_init(&ib, (integrator_kind_t)kind, 1, 1e-8, 10, &err) == 0);
    double worst = 0;
    for (int s = 0; s < 500; s++) {
      integrator_substep(&ia, &a.fs, 2e-3);
      integrator_substep(&ib, &b.fs, 2e-3);
      for (int c = 0; c < 3; c++) worst = fmax(worst, fabs(a.x[c] - b.x[c]) + fabs(a.v[c] - b.v[c]));
    }
    if (!(worst < 1e-12)) fprintf(stderr, "  %s: external spring differs by %g\n", integrator_name(kind), worst);
    CHECK(worst < 1e-12);
    integrator_destroy(&ia);
    integrator_destroy(&ib);
  }
}

static void test_names(void) {
  for (int k = 0; k < INT_COUNT; k++) CHECK(integrator_parse(integrator_name((integrator_kind_t)k)) == k);
  CHECK(integrator_parse("rk4") == INT_RK4);
  CHECK(integrator_parse("implicit_euler") == INT_IMPLICIT_EULER);
  CHECK(integrator_parse("leapfrog") == -1);
  CHECK(integrator_parse(NULL) == -1);
}

int main(void) {
  test_names();
  test_orders();
  test_implicit_exact();
  test_stable_dt();
  test_fixed_nodes();
  test_external_spring();
  return check_report("test_integrator");
}
