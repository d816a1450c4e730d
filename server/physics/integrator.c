/* SPDX-License-Identifier: Apache-2.0 */
/* integrator: one sub-step of a force_system_t with the scheme chosen in the
 * scene (see integrator.h for the list and their orders).
 *
 * External forces that depend on the state (the contact spring the model's
 * hook applies) are evaluated where the scheme evaluates the other forces:
 * pre_substep runs before the sub-step's first force evaluation, as
 * integrator.h promises, and again before each later evaluation at a new
 * state (Verlet's second kick, RK4's stages 2-4, for which the stage state
 * is put in s->x and s->v). Held constant over the sub-step, a contact
 * spring would be integrated by an explicit rule that is unstable without
 * damping (x += h v + h^2/2 a, v += h a: growth 1 + h^2 omega^2 / 2 per
 * step); with a 400 N/m probe on the spleen, Verlet and RK4 lost contact
 * within 21 steps that way.
 *
 * Fixed nodes (inv_mass 0) are masked everywhere: they are never written,
 * and the implicit solve runs on the free nodes only, so a pinned node is
 * an exact Dirichlet condition rather than a very heavy mass.
 *
 * The implicit step. With K = -dF/dx and C = -dF/dv, linearising
 * M dv = h F(x + h (v + dv), v + dv) about (x, v) gives
 *     (M + h C + h^2 K) dv = h (F - h K v)
 * (Baraff & Witkin 1998 write the same equation with dF/dx = -K, which is
 * where the "+ h K v" of the header's summary comes from). The matrix is
 * symmetric positive definite when K and C are (a force system hands out a
 * definite K for this purpose), so it is solved by conjugate gradients,
 * preconditioned with M^-1 (exact for the mass part; the models' masses are
 * equal today, but a model with unequal masses gets the scaling for free).
 * CG stops at ||r|| <= cg_tolerance ||b|| or after cg_max_iterations. */
#include "physics/integrator.h"

#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const NAMES[INT_COUNT] = {[INT_EXPLICIT_EULER] = "explicit_euler",
                                             [INT_SYMPLECTIC_EULER] = "symplectic_euler",
                                             [INT_VERLET] = "verlet",
                                             [INT_RK4] = "rk4",
                                             [INT_IMPLICIT_EULER] = "implicit_euler",
                                             [INT_IMPLICIT_PCG] = "implicit_pcg"};

/* Scratch arrays each scheme needs (3n doubles each). */
static const int NBUF[INT_COUNT] = {
    [INT_EXPLICIT_EULER] = 1, [INT_SYMPLECTIC_EULER] = 1, [INT_VERLET] = 1, [INT_RK4] = 5,
    [INT_IMPLICIT_EULER] = 7, [INT_IMPLICIT_PCG] = 7};

int integrator_parse(const char *name) {
  if (!name) return -1;
  for (int k = 0; k < INT_COUNT; k++)
    if (!strcmp(name, NAMES[k])) return k;
  return -1;
}

const char *integrator_name(integrator_kind_t k) { return (unsigned)k < INT_COUNT ? NAMES[k] : "unknown"; }

int integrator_init(integrator_t *it, integrator_kind_t kind, size_t n, double cg_tolerance, int cg_max_iterations,
                    verr_t *err) {
  memset(it, 0, sizeof *it);
  if ((unsigned)kind >= INT_COUNT) return verr_set(err, "integrator: unknown kind %d", (int)kind);
  if ((kind == INT_IMPLICIT_EULER || kind == INT_IMPLICIT_PCG) &&
      (!(cg_tolerance > 0 && cg_tolerance < 1) || cg_max_iterations < 1))
    return verr_set(err, "%s: cg_tolerance must be in (0, 1) and cg_max_iterations >= 1 (got %g, %d)", NAMES[kind],
                    cg_tolerance, cg_max_iterations);
  if (n > ((size_t)-1) / (3 * sizeof(double)) - 1) return verr_set(err, "integrator: %zu nodes is too many", n);
  it->kind = kind;
  it->n = n;
  it->cg_tolerance = cg_tolerance;
  it->cg_max_iterations = cg_max_iterations;
  for (int b = 0; b < NBUF[kind]; b++) {
    it->buf[b] = calloc(3 * n + 1, sizeof(double));
    if (!it->buf[b]) {
      integrator_destroy(it);
      return verr_set(err, "%s: out of memory for %zu nodes", NAMES[kind], n);
    }
  }
  return 0;
}

void integrator_destroy(integrator_t *it) {
  for (int b = 0; b < 8; b++) free(it->buf[b]);
  memset(it, 0, sizeof *it);
}

/* ---- explicit schemes --------------------------------------------------- */

static void explicit_euler(integrator_t *it, force_system_t *s, double h) {
  double *f = it->buf[0];
  s->forces(s, s->x, s->v, f);
  for (size_t i = 0; i < s->n; i++) {
    double w = s->inv_mass[i];
    if (w == 0) continue;
    for (int k = 0; k < 3; k++) {
      size_t c = 3 * i + k;
      s->x[c] += h * s->v[c];
      s->v[c] += h * w * f[c];
    }
  }
}

static void symplectic_euler(integrator_t *it, force_system_t *s, double h) {
  double *f = it->buf[0];
  s->forces(s, s->x, s->v, f);
  if (s->correct_v) { /* kick, implicit correction, drift */
    for (size_t i = 0; i < s->n; i++) {
      double w = s->inv_mass[i];
      if (w == 0) continue;
      for (int k = 0; k < 3; k++) s->v[3 * i + k] += h * w * f[3 * i + k];
    }
    s->correct_v(s, h);
    for (size_t i = 0; i < s->n; i++) {
      if (s->inv_mass[i] == 0) continue;
      for (int k = 0; k < 3; k++) s->x[3 * i + k] += h * s->v[3 * i + k];
    }
    return;
  }
  for (size_t i = 0; i < s->n; i++) {
    double w = s->inv_mass[i];
    if (w == 0) continue;
    for (int k = 0; k < 3; k++) {
      size_t c = 3 * i + k;
      s->v[c] += h * w * f[c];
      s->x[c] += h * s->v[c];
    }
  }
}

/* Kick-drift-kick. The second kick evaluates F at the new positions and the
 * half-step velocities, so the scheme is second order for forces that do
 * not depend on v and first order in the damping term. The end-of-step
 * force is not reused by the next sub-step: the next pre_substep may change
 * the external forces. */
static void verlet(integrator_t *it, force_system_t *s, double h) {
  double *f = it->buf[0];
  s->forces(s, s->x, s->v, f);
  for (size_t i = 0; i < s->n; i++) {
    double w = s->inv_mass[i];
    if (w == 0) continue;
    for (int k = 0; k < 3; k++) {
      size_t c = 3 * i + k;
      s->v[c] += 0.5 * h * w * f[c];
      s->x[c] += h * s->v[c];
    }
  }
  if (s->pre_substep) s->pre_substep(s);
  s->forces(s, s->x, s->v, f);
  for (size_t i = 0; i < s->n; i++) {
    double w = s->inv_mass[i];
    if (w == 0) continue;
    for (int k = 0; k < 3; k++) s->v[3 * i + k] += 0.5 * h * w * f[3 * i + k];
  }
}

/* Classical RK4 on y = (x, v), y' = (v, M^-1 F(x, v)). y_n is kept in
 * x0/v0 and each stage state is written into s->x and s->v, so that
 * pre_substep sees where the stage is; ax/av sum the weighted slopes. */
static void rk4(integrator_t *it, force_system_t *s, double h) {
  double *x0 = it->buf[0], *v0 = it->buf[1], *ax = it->buf[2], *av = it->buf[3], *f = it->buf[4];
  size_t n3 = 3 * s->n;
  static const double next_c[4] = {0.5, 0.5, 1.0, 0.0}; /* offset of the following stage, in h */
  static const double weight[4] = {1.0, 2.0, 2.0, 1.0};
  memcpy(x0, s->x, n3 * sizeof(double));
  memcpy(v0, s->v, n3 * sizeof(double));
  memset(ax, 0, n3 * sizeof(double));
  memset(av, 0, n3 * sizeof(double));
  for (int st = 0; st < 4; st++) {
    if (st > 0 && s->pre_substep) s->pre_substep(s); /* the first ran in integrator_substep */
    s->forces(s, s->x, s->v, f);
    double w = weight[st], c = next_c[st] * h;
    for (size_t i = 0; i < s->n; i++) {
      double im = s->inv_mass[i];
      if (im == 0) continue; /* fixed: slopes stay 0, the stage state stays x_n */
      for (int k = 0; k < 3; k++) {
        size_t j = 3 * i + k;
        double kx = s->v[j], kv = im * f[j];
        ax[j] += w * kx;
        av[j] += w * kv;
        s->x[j] = x0[j] + c * kx;
        s->v[j] = v0[j] + c * kv;
      }
    }
  }
  /* The last stage left s->x = x0, s->v = v0 on the free nodes. */
  for (size_t i = 0; i < s->n; i++) {
    if (s->inv_mass[i] == 0) continue;
    for (int k = 0; k < 3; k++) {
      size_t j = 3 * i + k;
      s->x[j] += h / 6.0 * ax[j];
      s->v[j] += h / 6.0 * av[j];
    }
  }
}

/* ---- implicit Euler ----------------------------------------------------- */

static double dot_free(const force_system_t *s, const double *a, const double *b) {
  double d = 0;
  for (size_t i = 0; i < s->n; i++) {
    if (s->inv_mass[i] == 0) continue;
    d += a[3 * i] * b[3 * i] + a[3 * i + 1] * b[3 * i + 1] + a[3 * i + 2] * b[3 * i + 2];
  }
  return d;
}

/* out = (M + h C + h^2 K) y on the free nodes, 0 on fixed ones. y must be 0
 * on fixed nodes, so the fixed columns drop out as well. */
static void system_mul(force_system_t *s, double h, const double *y, double *out) {
  s->stiffness_mul(s, s->x, h * h, h, y, out);
  for (size_t i = 0; i < s->n; i++) {
    double m = s->mass[i];
    for (int k = 0; k < 3; k++) {
      size_t c = 3 * i + k;
      out[c] = s->inv_mass[i] == 0 ? 0 : out[c] + m * y[c];
    }
  }
}

static void implicit_euler(integrator_t *it, force_system_t *s, double h) {
  double *b = it->buf[0], *dv = it->buf[1], *r = it->buf[2], *p = it->buf[3], *q = it->buf[4], *z = it->buf[5],
         *vm = it->buf[6];
  size_t n3 = 3 * s->n;
  it->last_cg_iterations = 0;
  it->last_cg_residual = 0;
  if (!s->stiffness_mul) { /* contract: the model refuses implicit_euler; stay safe anyway */
    symplectic_euler(it, s, h);
    return;
  }
  /* b = h F - h^2 K v, with the fixed nodes' velocities taken as 0. */
  for (size_t i = 0; i < s->n; i++)
    for (int k = 0; k < 3; k++) vm[3 * i + k] = s->inv_mass[i] == 0 ? 0 : s->v[3 * i + k];
  s->forces(s, s->x, s->v, b);
  s->stiffness_mul(s, s->x, h * h, 0, vm, q);
  for (size_t c = 0; c < n3; c++) b[c] = h * b[c] - q[c];
  for (size_t i = 0; i < s->n; i++)
    if (s->inv_mass[i] == 0) b[3 * i] = b[3 * i + 1] = b[3 * i + 2] = 0;

  /* Preconditioned CG from dv = 0, preconditioner M^-1. */
  memset(dv, 0, n3 * sizeof(double));
  memcpy(r, b, n3 * sizeof(double));
  double bnorm = sqrt(dot_free(s, b, b));
  if (bnorm > 0 && isfinite(bnorm)) {
    for (size_t c = 0; c < n3; c++) z[c] = r[c] * s->inv_mass[c / 3];
    memcpy(p, z, n3 * sizeof(double));
    double rz = dot_free(s, r, z), rnorm = bnorm;
    int iter = 0;
    while (iter < it->cg_max_iterations && rnorm > it->cg_tolerance * bnorm) {
      system_mul(s, h, p, q);
      double pq = dot_free(s, p, q);
      /* A is positive definite for a definite K; should curvature vanish
       * (or turn NaN) the iterate so far is the best there is. */
      if (!(pq > 0)) break;
      double alpha = rz / pq;
      for (size_t c = 0; c < n3; c++) {
        dv[c] += alpha * p[c];
        r[c] -= alpha * q[c];
      }
      iter++;
      rnorm = sqrt(dot_free(s, r, r));
      for (size_t c = 0; c < n3; c++) z[c] = r[c] * s->inv_mass[c / 3];
      double rz_new = dot_free(s, r, z);
      double beta = rz_new / rz;
      rz = rz_new;
      for (size_t c = 0; c < n3; c++) p[c] = z[c] + beta * p[c];
    }
    it->last_cg_iterations = iter;
    it->last_cg_residual = rnorm / bnorm;
  } else if (!isfinite(bnorm)) {
    /* Non-finite forces: let them reach the state so the caller's check
     * sees them and rolls the step back. */
    for (size_t c = 0; c < n3; c++) dv[c] = b[c];
    it->last_cg_residual = NAN;
  }
  for (size_t i = 0; i < s->n; i++) {
    if (s->inv_mass[i] == 0) continue;
    for (int k = 0; k < 3; k++) {
      size_t c = 3 * i + k;
      s->v[c] += dv[c];
      s->x[c] += h * s->v[c];
    }
  }
}

/* ---- implicit_pcg ------------------------------------------------------- */

/* out = A y = (M + A') y, from the force system's cache (every node) or
 * from stiffness_mul (fixed nodes 0). y must be 0 on the fixed nodes; the
 * caller ignores out there (its r and z are masked by dinv = 0). */
static void pcg_mul(force_system_t *s, double h, const double *y, double *out) {
  if (s->linear_mul) {
    s->linear_mul(s, y, out);
    return;
  }
  s->stiffness_mul(s, s->x, h * h, h, y, out);
  for (size_t i = 0; i < s->n; i++) {
    double m = s->mass[i];
    for (int k = 0; k < 3; k++) {
      size_t c = 3 * i + k;
      out[c] = s->inv_mass[i] == 0 ? 0 : out[c] + m * y[c];
    }
  }
}

/* The linearised backward-Euler step of implicit_euler with what makes it
 * cheap enough for one step per millisecond (integrator.h):
 *   - rhs, the Jacobian blocks and their diagonal in one pass over the
 *     springs (force_system_t.linearize) where the model offers it;
 *   - Jacobi preconditioner 1 / (m + diag A'): the stiff, high-frequency
 *     modes that a few iterations must get right are nearly local;
 *   - warm start from the last step's dv (buf[1] is kept between steps),
 *     scaled by the exact line search alpha = b.d / d.A d along it, so the
 *     start is never worse (in the A-norm CG minimises) than dv = 0, and a
 *     dv that no longer points anywhere useful (contact released, topology
 *     changed) costs one product, not a bad step;
 *   - at most cg_max_iterations (stopping earlier at cg_tolerance).
 * The tool springs are not in A: after the solve, correct_v takes them
 * implicitly with the rank-one solve of coupling.h (a splitting of the
 * tissue and tool stiffness; for a node of mass m, tissue stiffness kt and
 * tool stiffness k the step's amplification stays below 1 for any h, kt and
 * k). */
#define PCG_V_FLOOR 1e-8 /* m/s, see the stop test */

static void implicit_pcg(integrator_t *it, force_system_t *s, double h) {
  double *b = it->buf[0], *dv = it->buf[1], *r = it->buf[2], *p = it->buf[3], *q = it->buf[4], *z = it->buf[5],
         *dinv = it->buf[6];
  const size_t n = s->n, n3 = 3 * n;
  it->last_cg_iterations = 0;
  it->last_cg_residual = 0;
  if (!s->stiffness_mul && !s->linearize) {
    symplectic_euler(it, s, h);
    return;
  }
  if (s->linearize) {
    s->linearize(s, h, b, dinv);
  } else { /* b = h F - h^2 K v; diag of A' unknown: mass only */
    for (size_t c = 0; c < n3; c++) p[c] = s->inv_mass[c / 3] == 0 ? 0 : s->v[c];
    s->forces(s, s->x, s->v, b);
    s->stiffness_mul(s, s->x, h * h, 0, p, q);
    for (size_t c = 0; c < n3; c++) {
      b[c] = h * b[c] - q[c];
      dinv[c] = 0;
    }
  }
  for (size_t i = 0; i < n; i++)
    for (int k = 0; k < 3; k++) {
      size_t c = 3 * i + k;
      if (s->inv_mass[i] == 0) {
        b[c] = dv[c] = dinv[c] = 0;
      } else {
        double d = s->mass[i] + dinv[c];
        dinv[c] = d > 0 ? 1.0 / d : s->inv_mass[i];
      }
    }
  /* Fixed nodes: b = 0 and dinv = 0 there, so z, p and dv stay 0; r may
   * pick up A's rows there but only enters through z (masked). The stop
   * test is on the preconditioned residual r.z against b.D^-1 b. */
  double bz = 0;
  for (size_t c = 0; c < n3; c++) bz += b[c] * b[c] * dinv[c];
  /* Relative to b, with an absolute floor: at rest b is round-off and a
   * relative test would spend the whole budget on it. r.D^-1 r is about
   * sum m e^2 for a velocity error e, so the floor is an RMS error of
   * PCG_V_FLOOR m/s (100x below the settling tests' 1e-6 m/s); a b below
   * it is taken as dv = 0 without a product. */
  double mfree = 0;
  for (size_t i = 0; i < n; i++) mfree += s->inv_mass[i] == 0 ? 0 : s->mass[i];
  if (!isfinite(bz)) { /* let it reach the state: the caller's check rolls back */
    for (size_t c = 0; c < n3; c++) dv[c] = b[c];
    it->last_cg_residual = NAN;
  } else if (bz > 0 && bz > mfree * PCG_V_FLOOR * PCG_V_FLOOR) {
    /* Warm start: dv = alpha d, d the last dv, r = b - alpha A d. */
    double dd = dot_free(s, dv, dv), alpha = 0;
    if (!isfinite(dd)) memset(dv, 0, n3 * sizeof(double)); /* a rolled-back step's NaN */
    if (dd > 0 && isfinite(dd)) {
      pcg_mul(s, h, dv, q);
      double dad = dot_free(s, dv, q), bd = dot_free(s, b, dv);
      alpha = dad > 0 && bd > 0 && isfinite(dad) ? bd / dad : 0;
    }
    double rz = 0;
    for (size_t c = 0; c < n3; c++) {
      dv[c] *= alpha;
      r[c] = alpha != 0 ? b[c] - alpha * q[c] : b[c];
      z[c] = r[c] * dinv[c];
      p[c] = z[c];
      rz += r[c] * z[c];
    }
    const double stop = fmax(it->cg_tolerance * it->cg_tolerance * bz, mfree * PCG_V_FLOOR * PCG_V_FLOOR);
    int iter = 0;
    while (iter < it->cg_max_iterations && rz > stop) {
      pcg_mul(s, h, p, q);
      double pq = 0;
      for (size_t c = 0; c < n3; c++) pq += p[c] * q[c]; /* p = 0 on fixed nodes */
      if (!(pq > 0)) break;                              /* no curvature left (or NaN): keep what there is */
      double a = rz / pq, rz_new = 0;
      for (size_t c = 0; c < n3; c++) {
        dv[c] += a * p[c];
        r[c] -= a * q[c];
        z[c] = r[c] * dinv[c];
        rz_new += r[c] * z[c];
      }
      iter++;
      double beta = rz_new / rz;
      rz = rz_new;
      if (iter < it->cg_max_iterations && rz > stop)
        for (size_t c = 0; c < n3; c++) p[c] = z[c] + beta * p[c];
    }
    it->last_cg_iterations = iter;
    it->last_cg_residual = sqrt(rz / bz);
    it->cg_iterations_total += (uint64_t)iter;
  } else {
    memset(dv, 0, n3 * sizeof(double));
  }
  it->implicit_steps++;
  for (size_t i = 0; i < n; i++) {
    if (s->inv_mass[i] == 0) continue;
    for (int k = 0; k < 3; k++) s->v[3 * i + k] += dv[3 * i + k];
  }
  if (s->correct_v) s->correct_v(s, h);
  for (size_t i = 0; i < n; i++) {
    if (s->inv_mass[i] == 0) continue;
    for (int k = 0; k < 3; k++) s->x[3 * i + k] += h * s->v[3 * i + k];
  }
}

void integrator_substep(integrator_t *it, force_system_t *s, double h) {
  if (s->pre_substep) s->pre_substep(s);
  switch (it->kind) {
  case INT_EXPLICIT_EULER:
    explicit_euler(it, s, h);
    break;
  case INT_SYMPLECTIC_EULER:
    symplectic_euler(it, s, h);
    break;
  case INT_VERLET:
    verlet(it, s, h);
    break;
  case INT_RK4:
    rk4(it, s, h);
    break;
  case INT_IMPLICIT_EULER:
    implicit_euler(it, s, h);
    break;
  case INT_IMPLICIT_PCG:
    implicit_pcg(it, s, h);
    break;
  default:
    break;
  }
}

/* ---- stability bounds --------------------------------------------------- */

/* The bounds are those of the extreme mode x'' = -lk x - lc x' (omega^2 =
 * lk, damping rate lc). For a one-step map with 2x2 amplification matrix of
 * trace T and determinant D, both eigenvalues lie in the unit disc iff
 * |D| <= 1 and |T| <= 1 + D (Jury). */

/* Velocity Verlet on the mode: with a = 1 - h lc / 2 and b = h^2 lk / 2 the
 * matrix has D = a^2 and T = 1 - b + a^2 - a b. */
static int verlet_stable(double lk, double lc, double h) {
  double a = 1 - 0.5 * h * lc, b = 0.5 * h * h * lk;
  double D = a * a, T = 1 - b + a * a - a * b;
  return D <= 1 + 1e-12 && fabs(T) <= 1 + D + 1e-12;
}

/* RK4 on the mode: the eigenvalues of the step are R(h mu) for the mode's
 * eigenvalues mu = (-lc +- sqrt(lc^2 - 4 lk)) / 2, R(z) = 1 + z + z^2/2 +
 * z^3/6 + z^4/24. */
static int rk4_stable(double lk, double lc, double h) {
  double complex disc = csqrt((double complex)(lc * lc - 4 * lk));
  double complex mu[2] = {0.5 * (-lc + disc), 0.5 * (-lc - disc)};
  for (int i = 0; i < 2; i++) {
    double complex z = h * mu[i];
    double complex R = 1 + z * (1 + z * (0.5 + z * (1.0 / 6 + z / 24)));
    if (cabs(R) > 1 + 1e-12) return 0;
  }
  return 1;
}

/* Largest h with stable(h), found by stepping up from a small fraction of
 * the mode's time scale until the first failure, then bisecting; the
 * stability intervals of both schemes start at 0, so the first failure is
 * the bound. */
static double first_unstable(int (*stable)(double, double, double), double lk, double lc) {
  double scale = 1.0 / fmax(sqrt(lk), lc); /* > 0: the caller handles lk = lc = 0 */
  double lo = 1e-3 * scale, hi = lo;
  if (!stable(lk, lc, lo)) return 0;
  while (stable(lk, lc, hi)) {
    lo = hi;
    hi *= 1.05;
    if (hi > 100 * scale) return INFINITY; /* not reached for lk, lc >= 0 */
  }
  for (int i = 0; i < 60; i++) {
    double mid = 0.5 * (lo + hi);
    if (stable(lk, lc, mid))
      lo = mid;
    else
      hi = mid;
  }
  return lo;
}

double integrator_stable_dt(integrator_kind_t k, double lambda_k, double lambda_c) {
  double lk = fmax(lambda_k, 0), lc = fmax(lambda_c, 0);
  if (!isfinite(lk) || !isfinite(lc)) return 0;
  if (k == INT_IMPLICIT_EULER || k == INT_IMPLICIT_PCG) return INFINITY;
  if (lk == 0 && lc == 0) return INFINITY;
  switch (k) {
  case INT_EXPLICIT_EULER:
    /* Eigenvalues 1 + h mu. Under-damped (lc < 2 omega): |1 + h mu|^2 =
     * 1 - h lc + h^2 lk <= 1 iff h <= lc / lk, so 0 without damping (unstable
     * at every step). Over-damped: h <= 2 / |mu|max. */
    if (lc * lc < 4 * lk) return lc / lk;
    return 4.0 / (lc + sqrt(lc * lc - 4 * lk));
  case INT_SYMPLECTIC_EULER:
    /* D = 1 - h lc, T = 2 - h lc - h^2 lk: stable iff h lc <= 2 and
     * lk h^2 + 2 lc h - 4 <= 0; the positive root is the bound (the second
     * condition implies the first). */
    if (lk == 0) return 2.0 / lc;
    return (-lc + sqrt(lc * lc + 4 * lk)) / lk;
  case INT_VERLET:
    return first_unstable(verlet_stable, lk, lc);
  case INT_RK4:
    return first_unstable(rk4_stable, lk, lc);
  default:
    return 0;
  }
}

int integrator_choose_substeps(integrator_kind_t kind, double dt, int requested, double lk, double lc, double lk0,
                               double lc0, const char *advice, int *substeps, double *stable_dt, verr_t *err) {
  double stable = fmin(integrator_stable_dt(kind, lk, lc), integrator_stable_dt(kind, lk0, lc0));
  *stable_dt = stable;
  if (requested > 0) {
    if (requested > INTEGRATOR_MAX_SUBSTEPS)
      return verr_set(err, "solver.substeps %d exceeds the limit of %d", requested, INTEGRATOR_MAX_SUBSTEPS);
    *substeps = requested;
    return 0;
  }
  if (kind == INT_IMPLICIT_EULER || kind == INT_IMPLICIT_PCG) {
    *substeps = 1;
    return 0;
  }
  if (!(stable > 0))
    return verr_set(err, "%s is unstable at every step size here (no damping against omega_max = %.3g rad/s); %s",
                    integrator_name(kind), sqrt(lk), advice);
  double need = ceil(dt / (0.9 * stable));
  if (!(need <= INTEGRATOR_MAX_SUBSTEPS))
    return verr_set(err,
                    "%s is stable only below dt = %.3g s here (omega_max %.3g rad/s), which would need %.0f sub-steps "
                    "of the %.3g s step (limit %d); %s",
                    integrator_name(kind), stable, sqrt(lk), need, dt, INTEGRATOR_MAX_SUBSTEPS, advice);
  *substeps = need < 1 ? 1 : (int)need;
  return 0;
}
