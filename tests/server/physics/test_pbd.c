/* SPDX-License-Identifier: Apache-2.0 */
/* PBD / XPBD on tetrahedral meshes (server/physics/pbd.c, model_pbd.c):
 * constraint gradients against central differences; constraint forces
 * (weight carried by the fixed end, internal forces summing to zero);
 * recovery of a single tetrahedron and of the 30x5x5 bar from inverted,
 * flat, sliver, collapsed, scrambled, stretched and compressed starts
 * (docs/numerics.md §5 cases 6, 7, 8, 10); effective stiffness of the cantilever
 * against iterations (PBD drifts, XPBD does not); a 1:1000 mass-ratio chain
 * (case 3); NaN rollback (case 14); the model_t wrapper. Every run also
 * checks that no coordinate is ever NaN or Inf. Figures are printed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "physics/pbd.h"
#include "tet_mesh.h"
#include "vmath.h"

static unsigned rng_state = 20240611u;
static double urand(void) {
  rng_state = rng_state * 1664525u + 1013904223u;
  return (double)(rng_state >> 8) / 16777216.0;
}

static int state_finite(const pbd_t *s) {
  for (size_t c = 0; c < 3 * s->n; c++)
    if (!isfinite(s->x[c]) || !isfinite(s->v[c])) return 0;
  return 1;
}

static double max_speed(const pbd_t *s) {
  double m = 0;
  for (size_t i = 0; i < s->n; i++) m = fmax(m, v3_norm(s->v + 3 * i));
  return m;
}

static double rest_diag(const pbd_t *s) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < s->n; i++)
    for (int k = 0; k < 3; k++) {
      lo[k] = fmin(lo[k], s->x_rest[3 * i + k]);
      hi[k] = fmax(hi[k], s->x_rest[3 * i + k]);
    }
  double d[3];
  v3_sub(d, hi, lo);
  return v3_norm(d);
}

/* Eigen-decomposition of a symmetric 4x4 matrix by cyclic Jacobi rotations:
 * eigenvalues end on the diagonal of A, eigenvectors in the columns of V. */
static void jacobi4(double A[4][4], double V[4][4]) {
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) V[i][j] = i == j;
  for (int sweep = 0; sweep < 50; sweep++) {
    double off = 0;
    for (int p = 0; p < 4; p++)
      for (int q = p + 1; q < 4; q++) off += A[p][q] * A[p][q];
    if (off < 1e-30) break;
    for (int p = 0; p < 4; p++)
      for (int q = p + 1; q < 4; q++) {
        if (fabs(A[p][q]) < 1e-300) continue;
        double th = (A[q][q] - A[p][p]) / (2 * A[p][q]);
        double t = (th >= 0 ? 1 : -1) / (fabs(th) + sqrt(th * th + 1));
        double c = 1 / sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 4; k++) {
          double akp = A[k][p], akq = A[k][q];
          A[k][p] = c * akp - s * akq;
          A[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 4; k++) {
          double apk = A[p][k], aqk = A[q][k];
          A[p][k] = c * apk - s * aqk;
          A[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 4; k++) {
          double vkp = V[k][p], vkq = V[k][q];
          V[k][p] = c * vkp - s * vkq;
          V[k][q] = s * vkp + c * vkq;
        }
      }
  }
}

/* RMS distance between x and the best rigid motion of the rest shape
 * (Horn's quaternion method), over the rest bounding-box diagonal: "back
 * to rest" for a free body, whatever rigid motion it picked up. */
static double shape_error(const double *x, const double *r, size_t n, double size) {
  double xc[3] = {0, 0, 0}, rc[3] = {0, 0, 0};
  for (size_t i = 0; i < n; i++) {
    v3_axpy(xc, x + 3 * i, 1.0 / (double)n);
    v3_axpy(rc, r + 3 * i, 1.0 / (double)n);
  }
  double S[3][3] = {{0}};
  for (size_t i = 0; i < n; i++) {
    double a[3], b[3];
    v3_sub(a, r + 3 * i, rc);
    v3_sub(b, x + 3 * i, xc);
    for (int p = 0; p < 3; p++)
      for (int q = 0; q < 3; q++) S[p][q] += a[p] * b[q];
  }
  double N[4][4] = {{S[0][0] + S[1][1] + S[2][2], S[1][2] - S[2][1], S[2][0] - S[0][2], S[0][1] - S[1][0]},
                    {S[1][2] - S[2][1], S[0][0] - S[1][1] - S[2][2], S[0][1] + S[1][0], S[2][0] + S[0][2]},
                    {S[2][0] - S[0][2], S[0][1] + S[1][0], -S[0][0] + S[1][1] - S[2][2], S[1][2] + S[2][1]},
                    {S[0][1] - S[1][0], S[2][0] + S[0][2], S[1][2] + S[2][1], -S[0][0] - S[1][1] + S[2][2]}};
  double V[4][4];
  jacobi4(N, V);
  int best = 0;
  for (int k = 1; k < 4; k++)
    if (N[k][k] > N[best][best]) best = k;
  double w = V[0][best], qx = V[1][best], qy = V[2][best], qz = V[3][best];
  double R[3][3] = {{1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - w * qz), 2 * (qx * qz + w * qy)},
                    {2 * (qx * qy + w * qz), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - w * qx)},
                    {2 * (qx * qz - w * qy), 2 * (qy * qz + w * qx), 1 - 2 * (qx * qx + qy * qy)}};
  double e2 = 0;
  for (size_t i = 0; i < n; i++) {
    double a[3], b[3];
    v3_sub(a, r + 3 * i, rc);
    v3_sub(b, x + 3 * i, xc);
    for (int p = 0; p < 3; p++) {
      double d = R[p][0] * a[0] + R[p][1] * a[1] + R[p][2] * a[2] - b[p];
      e2 += d * d;
    }
  }
  return sqrt(e2 / (double)n) / size;
}

/* ---- gradients ----------------------------------------------------------- */

static void test_gradients(void) {
  double worst_d = 0, worst_v = 0, worst_sum = 0;
  for (int trial = 0; trial < 20; trial++) {
    double p[4][3], g[4][3], n[3], r[3] = {0.3, -0.2, 0.1}, r0[3] = {0, 0, 0};
    for (int a = 0; a < 4; a++)
      for (int k = 0; k < 3; k++) p[a][k] = 0.02 * (urand() - 0.5);
    double rest = 0.01 + 0.01 * urand(), V0 = 1e-6 * urand();
    /* Distance: dC/dx_i = n, dC/dx_j = -n. */
    pbd_distance_constraint(p[0], p[1], rest, r0, r, n);
    for (int k = 0; k < 3; k++) {
      double h = 1e-7, s0 = p[0][k];
      p[0][k] = s0 + h;
      double cp = pbd_distance_constraint(p[0], p[1], rest, r0, r, g[2]);
      p[0][k] = s0 - h;
      double cm = pbd_distance_constraint(p[0], p[1], rest, r0, r, g[2]);
      p[0][k] = s0;
      worst_d = fmax(worst_d, fabs((cp - cm) / (2 * h) - n[k]));
      s0 = p[1][k];
      p[1][k] = s0 + h;
      cp = pbd_distance_constraint(p[0], p[1], rest, r0, r, g[2]);
      p[1][k] = s0 - h;
      cm = pbd_distance_constraint(p[0], p[1], rest, r0, r, g[2]);
      p[1][k] = s0;
      worst_d = fmax(worst_d, fabs((cp - cm) / (2 * h) + n[k]));
    }
    /* Volume C = 6 (V - V0): every node, every axis. */
    pbd_volume_constraint(p[0], p[1], p[2], p[3], V0, g);
    double scale = 0;
    for (int a = 0; a < 4; a++) scale = fmax(scale, v3_norm(g[a]));
    for (int a = 0; a < 4; a++)
      for (int k = 0; k < 3; k++) {
        double h = 1e-7, s0 = p[a][k], gg[4][3];
        p[a][k] = s0 + h;
        double cp = pbd_volume_constraint(p[0], p[1], p[2], p[3], V0, gg);
        p[a][k] = s0 - h;
        double cm = pbd_volume_constraint(p[0], p[1], p[2], p[3], V0, gg);
        p[a][k] = s0;
        worst_v = fmax(worst_v, fabs((cp - cm) / (2 * h) - g[a][k]) / scale);
      }
    /* Gradients of an internal constraint sum to zero (momentum). */
    double sum[3] = {0, 0, 0};
    for (int a = 0; a < 4; a++) v3_add(sum, sum, g[a]);
    worst_sum = fmax(worst_sum, v3_norm(sum) / scale);
  }
  printf("gradients vs central differences: distance %.2e, volume %.2e (relative), volume sum %.1e\n", worst_d, worst_v,
         worst_sum);
  CHECK(worst_d < 1e-6);
  CHECK(worst_v < 1e-6);
  CHECK(worst_sum < 1e-12);

  /* Degenerate distance: coincident nodes take the rest direction, finite. */
  double a[3] = {0.1, 0.1, 0.1}, ri[3] = {0, 0, 0.02}, rj[3] = {0, 0, 0}, n[3];
  double C = pbd_distance_constraint(a, a, 0.02, ri, rj, n);
  CHECK_NEAR(C, -0.02, 1e-15);
  CHECK_NEAR(n[2], 1, 1e-15);
  /* ...and coincident at rest too: no direction at all, zero, never NaN. */
  C = pbd_distance_constraint(a, a, 0, a, a, n);
  CHECK(C == 0 && n[0] == 0 && n[1] == 0 && n[2] == 0);
  /* Rest-state values: C = 0. */
  double t[4][3] = {{0, 0, 0}, {0.01, 0, 0}, {0, 0.01, 0}, {0, 0, 0.01}}, g[4][3];
  CHECK_NEAR(pbd_volume_constraint(t[0], t[1], t[2], t[3], 1e-6 / 6, g), 0, 1e-18);
  /* All four nodes on one point: zero gradient, C = -6 V0, finite. */
  double c = pbd_volume_constraint(t[0], t[0], t[0], t[0], 1e-6 / 6, g);
  CHECK_NEAR(c, -1e-6, 1e-18);
  CHECK(v3_norm(g[0]) == 0 && v3_norm(g[3]) == 0);
}

/* ---- set-ups -------------------------------------------------------------- */

/* The recovery material: free body (no gravity, no home), sub-step 1 ms,
 * damping 20 /s relative to the ground; XPBD compliance, or PBD with
 * stiffness 1 (rigid constraints). */
static pbd_params_t recovery_params(pbd_mode_t mode, double mass, int iterations) {
  pbd_params_t p = {.mode = mode,
                    .mass = mass,
                    .distance_stiffness = 1,
                    .volume_stiffness = 1,
                    .distance_compliance = 1e-4,
                    .volume_compliance = 1e-10,
                    .substeps = 5,
                    .iterations = iterations,
                    .stiffness_correction = 1};
  return p;
}

static int make_bar(pbd_t *s, size_t nx, size_t ny, size_t nz, double h, const pbd_params_t *p) {
  tet_mesh_t tm;
  verr_t err;
  memset(s, 0, sizeof *s);
  if (tet_mesh_box_grid(nx, ny, nz, h, &tm, &err)) {
    fprintf(stderr, "%s\n", err.msg);
    return -1;
  }
  int rc = pbd_create(s, tm.nnodes, tm.x, tm.ntets, tm.tets, p, &err);
  if (rc) fprintf(stderr, "%s\n", err.msg);
  tet_mesh_free(&tm);
  if (!rc) s->p.damping = 20 * s->mass[0]; /* 20 /s */
  return rc;
}

static int make_tet(pbd_t *s, const pbd_params_t *p) {
  /* A regular tetrahedron of edge 2 cm, positively oriented. */
  const double e = 0.02;
  double x[12] = {0, 0, 0, e, 0, 0, e / 2, e * sqrt(3) / 2, 0, e / 2, e * sqrt(3) / 6, e * sqrt(2.0 / 3)};
  uint32_t t[4] = {0, 1, 2, 3};
  verr_t err;
  int rc = pbd_create(s, 4, x, 1, t, p, &err);
  if (rc) fprintf(stderr, "%s\n", err.msg);
  if (!rc) s->p.damping = 20 * s->mass[0];
  return rc;
}

typedef struct run_result {
  double t_positive;  /* s, since when every tet has been positive (INFINITY: not at the end) */
  double t_shape;     /* s, first time the shape error is <= 1 % (INFINITY: never) */
  double vmax;        /* m/s, largest node speed seen */
  double final_shape; /* shape error at the end */
  double final_volume;
  int finite; /* never NaN or Inf */
  int rollbacks;
} run_result_t;

/* Steps for up to `seconds` (dt 5 ms), recording when the mesh became
 * positive and when the shape came back to rest; stops 0.5 s after both. */
static run_result_t run(pbd_t *s, double seconds) {
  run_result_t r = {INFINITY, INFINITY, 0, 0, 0, 1, 0};
  double size = rest_diag(s), dt = 0.005;
  int steps = (int)(seconds / dt + 0.5), settle = -1;
  for (int k = 1; k <= steps; k++) {
    if (pbd_step(s, dt, NULL, NULL)) r.rollbacks++;
    if (!state_finite(s)) r.finite = 0;
    r.vmax = fmax(r.vmax, max_speed(s));
    double t = k * dt;
    /* t_positive: since when every tetrahedron has stayed positive. */
    pbd_errors_t e;
    pbd_errors(s, &e);
    if (e.inverted)
      r.t_positive = INFINITY;
    else if (r.t_positive == INFINITY)
      r.t_positive = t;
    if (r.t_shape == INFINITY && k % 4 == 0 && shape_error(s->x, s->x_rest, s->n, size) <= 0.01) r.t_shape = t;
    if (settle < 0 && r.t_positive < INFINITY && r.t_shape < INFINITY) settle = k + (int)(0.5 / dt);
    if (k == settle) break;
  }
  r.final_shape = shape_error(s->x, s->x_rest, s->n, size);
  r.final_volume = pbd_volume_error(s);
  return r;
}

static void report(const char *what, const run_result_t *r) {
  printf("  %-34s positive from %6.3f s, shape <= 1%% at %6.3f s, final shape %.2e, volume %.2e, vmax %.3g m/s%s\n",
         what, r->t_positive, r->t_shape, r->final_shape, r->final_volume, r->vmax, r->finite ? "" : "  NON-FINITE");
}

/* A recovered run: finite, never rolled back, every tet positive within
 * 1 s, back to the rest shape within `shape_s` s, and staying there. */
static void check_recovered(const run_result_t *r, double shape_s) {
  CHECK(r->finite);
  CHECK(r->rollbacks == 0);
  CHECK(r->t_positive <= 1.0);
  CHECK(r->t_shape <= shape_s);
  CHECK(r->final_shape <= 0.01);
  CHECK(r->final_volume <= 0.01);
}

/* ---- single tetrahedron --------------------------------------------------- */

static const char *mode_name(pbd_mode_t m) { return m == PBD_MODE_XPBD ? "XPBD" : "PBD"; }

static void test_single_tet(pbd_mode_t mode) {
  printf("single tetrahedron (edge 2 cm, 1 g, %s, dt 5 ms, 5 sub-steps x 3 iterations):\n", mode_name(mode));
  pbd_params_t p = recovery_params(mode, 0.001, 3);
  pbd_t s;
  double size;

  /* Shape error of a rigidly moved rest shape is zero (checks the metric). */
  CHECK(make_tet(&s, &p) == 0);
  size = rest_diag(&s);
  for (size_t i = 0; i < 4; i++) {
    const double *r = s.x_rest + 3 * i;
    v3_set(s.x + 3 * i, 0.3 - r[1], r[0] + 0.1, r[2] - 0.2); /* 90 degrees about z, moved */
  }
  CHECK(shape_error(s.x, s.x_rest, 4, size) < 1e-12);
  pbd_destroy(&s);

  const char *names[] = {"inverted (node through its face)",
                         "flat (node on its face)",
                         "sliver (square corners)",
                         "collapsed to a point",
                         "scrambled",
                         "needle (nodes on a line)"};
  for (int c = 0; c < 6; c++) {
    CHECK(make_tet(&s, &p) == 0);
    size = rest_diag(&s);
    double *x = s.x;
    if (c == 0) x[11] = -x[11];
    if (c == 1) x[11] = 0;
    if (c == 2) { /* four corners of a square, 1e-6 apart in height, inverted */
      double sq[12] = {0, 0, 0, 0.02, 0.02, 0, 0.02, 0, 1e-6, 0, 0.02, 1e-6};
      memcpy(x, sq, sizeof sq);
    }
    if (c == 3)
      for (int i = 0; i < 12; i++) x[i] = 0.01;
    if (c == 4)
      for (int i = 0; i < 12; i++) x[i] = 0.02 * urand();
    if (c == 5)
      for (int i = 0; i < 4; i++) v3_set(x + 3 * i, 0.005 * i, 0.005 * i, 1e-9 * (i == 2));
    run_result_t r = run(&s, 5);
    report(names[c], &r);
    check_recovered(&r, 5);
    /* Bounded speed: no node faster than a size per sub-step. */
    CHECK(r.vmax <= size / 0.001);
    pbd_destroy(&s);
  }
}

/* ---- the 30 x 5 x 5 bar ---------------------------------------------------- */

static void test_bar_recovery(pbd_mode_t mode) {
  printf("bar 30x5x5 nodes (h 1 cm, 0.5 kg, free, %s, dt 5 ms, 5 sub-steps x 3 iterations):\n", mode_name(mode));
  pbd_params_t p = recovery_params(mode, 0.5, 3);
  pbd_t s;
  CHECK(make_bar(&s, 30, 5, 5, 0.01, &p) == 0);
  CHECK(s.n == 750 && s.ntets == 2320 && s.nedges == 3565);
  pbd_errors_t e;
  pbd_errors(&s, &e);
  CHECK(e.inverted == 0 && e.strain_max < 1e-12 && e.volume_global < 1e-12);
  double size = rest_diag(&s);
  pbd_destroy(&s);

  /* 10 % inverted: reflect random nodes through the opposite face of one of
   * their tetrahedra until at least 10 % of the tetrahedra are inverted. */
  {
    CHECK(make_bar(&s, 30, 5, 5, 0.01, &p) == 0);
    for (int guard = 0; guard < 100000; guard++) {
      pbd_errors(&s, &e);
      if (e.inverted * 10 >= s.ntets) break;
      size_t t = (size_t)(urand() * (double)s.ntets) % s.ntets;
      int a = (int)(urand() * 4) % 4;
      const uint32_t *q = s.tet + 4 * t;
      double *pa = s.x + 3 * q[a], *f0 = s.x + 3 * q[(a + 1) % 4], *f1 = s.x + 3 * q[(a + 2) % 4],
             *f2 = s.x + 3 * q[(a + 3) % 4], u[3], v[3], nrm[3], d[3];
      v3_sub(u, f1, f0);
      v3_sub(v, f2, f0);
      v3_cross(nrm, u, v);
      v3_normalize(nrm);
      v3_sub(d, pa, f0);
      v3_axpy(pa, nrm, -2 * v3_dot(d, nrm));
    }
    pbd_errors(&s, &e);
    printf("  start: %zu of %zu tetrahedra inverted (%.1f %%), min V/V0 %.2f\n", e.inverted, s.ntets,
           100.0 * (double)e.inverted / (double)s.ntets, e.min_volume_ratio);
    CHECK(e.inverted * 10 >= s.ntets);
    run_result_t r = run(&s, 5);
    report("10 % inverted", &r);
    check_recovered(&r, 5);
    pbd_destroy(&s);
  }

  const char *names[] = {"collapsed to a point", "scrambled in the bounding box", "stretched to 2x",
                         "stretched to 5x",      "compressed to 10 % volume",     "flattened (all tets flat)"};
  for (int c = 0; c < 6; c++) {
    CHECK(make_bar(&s, 30, 5, 5, 0.01, &p) == 0);
    for (size_t i = 0; i < s.n; i++) {
      double *x = s.x + 3 * i;
      if (c == 0) v3_set(x, 0.1, 0.02, 0.02);
      if (c == 1) v3_set(x, 0.29 * urand(), 0.04 * urand(), 0.04 * urand());
      if (c == 2) x[0] *= 2;
      if (c == 3) x[0] *= 5;
      if (c == 4) x[0] *= 0.1;
      if (c == 5) x[2] = 0;
    }
    if (c == 4) {
      pbd_errors(&s, &e);
      CHECK_NEAR(e.volume_global, 0.9, 1e-9);
    }
    run_result_t r = run(&s, 5);
    report(names[c], &r);
    CHECK(r.vmax <= size / 0.001);
    if (mode == PBD_MODE_PBD && c <= 1 && r.final_shape > 0.01) {
      /* Rigid PBD constraints projected one by one can stop in a locally
       * twisted, self-consistent state (positive tetrahedra, strained
       * edges): Gauss-Seidel on hard constraints has fixed points that are
       * no energy minimum. Seen in 1 of 30 collapsed/scrambled starts at
       * stiffness 1 (11 of 30 at 0.9), never with XPBD. Reported, and only
       * positivity and finiteness are required of PBD here. */
      printf("    PBD locked in a twisted state (max strain %.2f): expected for some starts, XPBD recovers\n",
             (pbd_errors(&s, &e), e.strain_max));
      CHECK(r.finite && r.rollbacks == 0 && r.t_positive <= 1.0);
    } else
      check_recovered(&r, 5);
    pbd_destroy(&s);
  }
}

/* ---- effective stiffness: cantilever sag against iterations ---------------- */

/* Mean sag of the free end after `seconds`: bar 30x5x5 (h 1 cm, 0.5 kg),
 * the x = 0 face fixed, gravity -z, dt 10 ms in 10 sub-steps, damping
 * 16 /s (about critical for the first bending mode, so 0.8 s is static
 * within 0.5 %). XPBD compliance 1e-3 m/N per edge, 1e-9 per volume. */
static double cantilever_sag(pbd_mode_t mode, int iterations, double seconds, double *force_err, double *internal) {
  pbd_params_t p = {.mode = mode,
                    .mass = 0.5,
                    .distance_stiffness = 1,
                    .volume_stiffness = 1,
                    .distance_compliance = 1e-3,
                    .volume_compliance = 1e-9,
                    .gravity = {0, 0, -9.81},
                    .substeps = 10,
                    .iterations = iterations,
                    .stiffness_correction = 1};
  pbd_t s;
  if (force_err) *force_err = NAN;
  if (internal) *internal = NAN;
  if (make_bar(&s, 30, 5, 5, 0.01, &p)) return NAN;
  s.p.damping = 16 * s.mass[0];
  CHECK(pbd_fix_below(&s, -1) == 0);
  size_t fixed = 0;
  for (size_t i = 0; i < s.n; i++)
    if (s.x_rest[3 * i] < 1e-9) {
      pbd_fix_node(&s, i);
      fixed++;
    }
  CHECK(fixed == 25);
  int ok = 1;
  for (int k = 0; k < (int)(seconds / 0.01 + 0.5); k++) ok &= pbd_step(&s, 0.01, NULL, NULL) == 0 && state_finite(&s);
  CHECK(ok);
  double sag = 0;
  for (size_t i = 0; i < s.n; i++)
    if (s.x_rest[3 * i] > 0.285) sag += (s.x_rest[3 * i + 2] - s.x[3 * i + 2]) / 25;
  /* Constraint forces (haptics): the fixed face carries the weight of the
   * rest of the bar, and the internal forces over all nodes cancel. */
  uint32_t *nodes = malloc(s.n * sizeof *nodes);
  size_t nf = 0;
  for (size_t i = 0; i < s.n; i++)
    if (s.inv_mass[i] == 0) nodes[nf++] = (uint32_t)i;
  double f[3], weight = 9.81 * s.mass[0] * (double)(s.n - nf);
  pbd_constraint_force(&s, nodes, nf, f);
  if (force_err) *force_err = fabs(-f[2] / weight - 1);
  for (size_t i = 0; i < s.n; i++) nodes[i] = (uint32_t)i;
  if (internal) *internal = pbd_constraint_force(&s, nodes, s.n, NULL) / weight;
  free(nodes);
  pbd_destroy(&s);
  return sag;
}

static void test_cantilever(void) {
  double f5, f50, internal;
  double x5 = cantilever_sag(PBD_MODE_XPBD, 5, 0.8, &f5, NULL),
         x50 = cantilever_sag(PBD_MODE_XPBD, 50, 0.8, &f50, &internal);
  double p5 = cantilever_sag(PBD_MODE_PBD, 5, 0.5, NULL, NULL), p50 = cantilever_sag(PBD_MODE_PBD, 50, 0.5, NULL, NULL);
  printf("cantilever 30x5x5 tip sag (dt 10 ms, 10 sub-steps): XPBD %.2f mm (5 it) vs %.2f mm (50 it), %+.1f %%; "
         "PBD %.2f mm vs %.2f mm, x%.1f\n",
         1e3 * x5, 1e3 * x50, 100 * (x5 / x50 - 1), 1e3 * p5, 1e3 * p50, p5 / p50);
  /* XPBD: the stiffness is the compliance's, whatever the iteration count. */
  CHECK(fabs(x5 / x50 - 1) <= 0.05);
  /* PBD: rigid constraints that only converge as far as the iterations go:
   * the bar is much stiffer with 50. */
  CHECK(p5 / p50 >= 3);
  CHECK(x50 > 0.05 && x50 < 0.29);
  printf("  XPBD constraint force on the fixed face vs the weight it holds: %.2f %% off (5 it), %.2f %% (50 it); "
         "sum over all nodes %.1e of the weight\n",
         100 * f5, 100 * f50, internal);
  CHECK(f50 <= 0.02);
  CHECK(internal <= 1e-9);
}

/* ---- mass ratio 1:1000 chain ------------------------------------------------ */

/* A chain of 20 cells (21x2x2 nodes, h 1 cm) hanging along +x from its
 * fixed top face, light nodes of 1 g and the bottom face 1 kg each, near
 * rigid (compliance 1e-8 m/N: 0.04 % strain under the load), at the scene
 * rate dt 1 ms for 1.5 s. Gauss-Seidel hardly moves a heavy node from a
 * light one, so the error comes from the sub-step length: many sub-steps
 * of one iteration keep it small, the same cost in iterations does not. */
static double chain_strain(int substeps, int iterations) {
  pbd_params_t p = {.mode = PBD_MODE_XPBD,
                    .mass = 0.16,
                    .distance_compliance = 1e-8,
                    .volume_compliance = 1e-12,
                    .gravity = {9.81, 0, 0}, /* "down" is +x: it hangs from the x = 0 face */
                    .substeps = substeps,
                    .iterations = iterations};
  pbd_t s;
  if (make_bar(&s, 21, 2, 2, 0.01, &p)) return NAN;
  for (size_t i = 0; i < s.n; i++) {
    double x = s.x_rest[3 * i];
    pbd_set_node_mass(&s, i, x > 0.195 ? 1.0 : 0.001);
    if (x < 1e-9) pbd_fix_node(&s, i);
  }
  s.p.damping = 0.001 * 5; /* 5 /s on the light nodes */
  int ok = 1;
  for (int k = 0; k < 1500; k++) ok &= pbd_step(&s, 0.001, NULL, NULL) == 0 && state_finite(&s);
  CHECK(ok);
  pbd_errors_t e;
  pbd_errors(&s, &e);
  pbd_destroy(&s);
  return e.strain_max;
}

static void test_mass_ratio_chain(void) {
  double sub = chain_strain(20, 1), it = chain_strain(1, 20);
  printf("mass ratio 1:1000 chain (21x2x2, 1 g / 1 kg nodes, XPBD, dt 1 ms): max strain %.3f %% with 20 sub-steps x "
         "1 iteration, %.3f %% with 1 x 20\n",
         100 * sub, 100 * it);
  CHECK(sub <= 0.01);
  CHECK(it > sub);
}

/* ---- rollback ---------------------------------------------------------------- */

static void test_rollback(void) {
  pbd_params_t p = recovery_params(PBD_MODE_XPBD, 0.5, 2);
  p.gravity[2] = -9.81;
  p.home_stiffness = 30;
  pbd_t s;
  CHECK(make_bar(&s, 10, 3, 3, 0.01, &p) == 0);
  for (int k = 0; k < 10; k++) CHECK(pbd_step(&s, 0.005, NULL, NULL) == 0);
  double *before = malloc(6 * s.n * sizeof(double));
  memcpy(before, s.x, 3 * s.n * sizeof(double));
  memcpy(before + 3 * s.n, s.v, 3 * s.n * sizeof(double));
  /* A non-finite external force: the step fails and the state is as before. */
  double bad[3] = {NAN, 0, 0};
  pbd_add_force(&s, 7, bad);
  CHECK(pbd_step(&s, 0.005, NULL, NULL) == -1);
  CHECK(s.rollbacks == 1);
  CHECK(memcmp(before, s.x, 3 * s.n * sizeof(double)) == 0);
  CHECK(memcmp(before + 3 * s.n, s.v, 3 * s.n * sizeof(double)) == 0);
  double f[3];
  uint32_t node = 7;
  CHECK(pbd_constraint_force(&s, &node, 1, f) == 0);
  /* The next step is clean (the bad force was dropped). */
  CHECK(pbd_step(&s, 0.005, NULL, NULL) == 0);
  /* A NaN injected into a node: detected within the step, rolled back; the
   * node goes back to rest so nothing spreads and stepping continues. */
  s.x[3 * 5 + 1] = NAN;
  CHECK(pbd_step(&s, 0.005, NULL, NULL) == -1);
  CHECK(state_finite(&s));
  CHECK(v3_dist(s.x + 15, s.x_rest + 15) == 0);
  for (int k = 0; k < 20; k++) CHECK(pbd_step(&s, 0.005, NULL, NULL) == 0);
  CHECK(state_finite(&s));
  /* A non-finite step length is refused the same way. */
  CHECK(pbd_step(&s, NAN, NULL, NULL) == -1);
  CHECK(s.rollbacks == 3);
  CHECK(state_finite(&s));
  free(before);
  pbd_destroy(&s);

  /* Bad parameters and meshes are refused with a message. */
  verr_t err;
  double x[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  uint32_t t[4] = {0, 1, 2, 3}, tbad[4] = {0, 1, 2, 4};
  pbd_params_t q = recovery_params(PBD_MODE_PBD, 1, 1);
  CHECK(pbd_create(&s, 4, x, 1, tbad, &q, &err) == -1 && strstr(err.msg, "node 4"));
  q.distance_stiffness = 1.5;
  CHECK(pbd_create(&s, 4, x, 1, t, &q, &err) == -1 && strstr(err.msg, "0..1"));
  q = recovery_params(PBD_MODE_XPBD, 1, 0);
  CHECK(pbd_create(&s, 4, x, 1, t, &q, &err) == -1 && strstr(err.msg, "iterations"));
  q = recovery_params(PBD_MODE_XPBD, 0, 1);
  CHECK(pbd_create(&s, 4, x, 1, t, &q, &err) == -1 && strstr(err.msg, "mass"));
}

/* ---- model_t wrapper ------------------------------------------------------- */

static void cube(mesh_t *m, double a) {
  static const uint32_t T[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                                    {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  mesh_alloc(m, 8, 12, NULL);
  for (int i = 0; i < 8; i++) v3_set(m->pos + 3 * i, a * ((i & 1) ^ (i >> 1 & 1)), a * (i >> 1 & 1), a * (i >> 2));
  memcpy(m->tris, T, sizeof T);
}

typedef struct push {
  uint32_t vertex;
  double f[3];
  int calls;
} push_t;

static void push_hook(model_t *m, void *ctx) {
  push_t *p = ctx;
  p->calls++;
  m->ops->add_surface_force(m, p->vertex, p->f);
}

static void test_model(void) {
  mesh_t surf;
  cube(&surf, 0.04);
  CHECK(mesh_signed_volume(&surf) > 0);
  scene_organ_t cfg;
  memset(&cfg, 0, sizeof cfg);
  snprintf(cfg.name, sizeof cfg.name, "cube");
  snprintf(cfg.model, sizeof cfg.model, "xpbd");
  cfg.material = (scene_material_t){.mass = 0.1,
                                    .home_stiffness = 30,
                                    .home_damping = 0.005,
                                    .distance_stiffness = 1,
                                    .volume_stiffness = 1,
                                    .distance_compliance = 1e-4,
                                    .volume_compliance = 1e-6};
  cfg.solver = (scene_solver_t){.substeps = 0, .iterations = 5, .tet_size = 0.01};
  model_params_t mp = {.cfg = &cfg, .surface = &surf, .gravity = {0, 0, 0}, .dt = 0.002, .tool_stiffness = 300};
  verr_t err;
  model_t *m = model_pbd_create(&mp, &err);
  CHECK(m != NULL);
  if (!m) {
    fprintf(stderr, "%s\n", err.msg);
    mesh_free(&surf);
    return;
  }
  CHECK(!strcmp(m->ops->name, "xpbd"));
  CHECK(!strcmp(m->error_kind, "volume_error"));
  CHECK(m->nnodes > 8 && m->ntets > 0);
  CHECK(m->nsurf == 8 && m->nsurf_tris == 12);
  CHECK(isinf(m->stable_dt) && m->stable_dt > 0);
  CHECK(m->substeps == 2); /* auto: 1 ms sub-steps */
  double worst = 0;
  for (size_t c = 0; c < 3 * m->nsurf; c++) worst = fmax(worst, fabs(m->surf_x[c] - m->surf_rest[c]));
  CHECK(worst < 1e-12);
  CHECK(m->ops->error_estimate(m) < 1e-12);
  CHECK(isfinite(m->ops->energy(m)));
  printf("model xpbd on a 4 cm cube: %zu nodes, %zu tetrahedra, %d sub-steps\n", m->nnodes, m->ntets, m->substeps);

  /* Press the top corner (vertex 6, z = a) down with 1 N, through the hook. */
  push_t push = {6, {0, 0, -1}, 0};
  m->hook = push_hook;
  m->hook_ctx = &push;
  int ok = 1;
  for (int k = 0; k < 200; k++) ok &= m->ops->step(m, 0.002) == 0;
  CHECK(ok);
  CHECK(push.calls == 400); /* once per sub-step */
  double dz = m->surf_x[3 * 6 + 2] - m->surf_rest[3 * 6 + 2];
  printf("  1 N on a corner: it moves %.2f mm, volume error %.2e\n", 1e3 * dz, m->ops->error_estimate(m));
  CHECK(dz < -1e-4);
  CHECK(m->ops->error_estimate(m) < 0.05);
  /* Released, the home springs bring it back. */
  m->hook = NULL;
  for (int k = 0; k < 1000; k++) ok &= m->ops->step(m, 0.002) == 0;
  CHECK(ok);
  worst = 0;
  for (size_t c = 0; c < 3 * m->nsurf; c++) worst = fmax(worst, fabs(m->surf_x[c] - m->surf_rest[c]));
  CHECK(worst < 1e-4);
  /* A NaN in a node: rolled back, counted, the surface stays finite. */
  m->x[0] = NAN;
  model_note_outside_write(m);
  CHECK(m->ops->step(m, 0.002) == -1);
  CHECK(m->rollbacks == 1);
  for (size_t c = 0; c < 3 * m->nsurf; c++) CHECK(isfinite(m->surf_x[c]));
  model_destroy(m);

  /* PBD: no energy; fixed_below pins the bottom nodes. */
  snprintf(cfg.model, sizeof cfg.model, "pbd");
  cfg.fixed_below_set = 1;
  cfg.fixed_below = 0.001;
  m = model_pbd_create(&mp, &err);
  CHECK(m != NULL);
  if (m) {
    CHECK(!strcmp(m->ops->name, "pbd"));
    CHECK(isnan(m->ops->energy(m)));
    mp.gravity[2] = -9.81;
    model_destroy(m);
  }
  /* ...and with gravity the bottom stays put. */
  m = model_pbd_create(&mp, &err);
  CHECK(m != NULL);
  if (m) {
    for (int k = 0; k < 100; k++) m->ops->step(m, 0.002);
    CHECK(m->surf_x[2] == m->surf_rest[2]);
    CHECK(m->surf_x[3 * 6 + 2] < m->surf_rest[3 * 6 + 2]);
    model_destroy(m);
  }
  /* Not a PBD model name: refused. */
  snprintf(cfg.model, sizeof cfg.model, "molecular");
  CHECK(model_pbd_create(&mp, &err) == NULL && strstr(err.msg, "molecular"));
  mesh_free(&surf);
}

/* ---- constraint order and the four-wide sweep ------------------------------ */

static int shares_node(const uint32_t *a, const uint32_t *b, int arity) {
  for (int i = 0; i < arity; i++)
    for (int j = 0; j < arity; j++)
      if (a[i] == b[j]) return 1;
  return 0;
}

/* Within a colour no two constraints share a node (what makes the sweep's
 * order and the four-wide volume projection safe), and the four-wide path
 * gives bit-identical results to the scalar loop. */
static void test_order(void) {
  pbd_params_t p = recovery_params(PBD_MODE_XPBD, 0.5, 2);
  p.gravity[2] = -9.81;
  pbd_t a, b;
  CHECK(make_bar(&a, 30, 5, 5, 0.01, &p) == 0);
  int clash = 0, ncol = 0;
  for (int c = 0; c < PBD_COLOURS - 1; c++) {
    ncol += a.tet_colour[c + 1] > a.tet_colour[c];
    for (size_t i = a.tet_colour[c]; i < a.tet_colour[c + 1]; i++)
      for (size_t j = i + 1; j < a.tet_colour[c + 1]; j++) clash += shares_node(a.tet + 4 * i, a.tet + 4 * j, 4);
    for (size_t i = a.edge_colour[c]; i < a.edge_colour[c + 1]; i++)
      for (size_t j = i + 1; j < a.edge_colour[c + 1]; j++) clash += shares_node(a.edge + 2 * i, a.edge + 2 * j, 2);
  }
  CHECK(clash == 0);
  CHECK(a.tet_colour[PBD_COLOURS] == a.ntets && a.edge_colour[PBD_COLOURS] == a.nedges);
  CHECK(a.tet_colour[PBD_COLOURS - 1] == a.ntets); /* no overflow on the bar */
  printf("constraint colours on the bar: %d for tetrahedra, no shared node within one; four-wide sweep %s\n", ncol,
         a.simd ? "available" : "not available on this CPU");
  CHECK(make_bar(&b, 30, 5, 5, 0.01, &p) == 0);
  b.simd = 0;
  for (size_t i = 0; i < a.n; i++)
    if (a.x_rest[3 * i] < 1e-9) {
      pbd_fix_node(&a, i);
      pbd_fix_node(&b, i);
    }
  /* A rough start so the cap and every branch take part. */
  for (size_t c = 0; c < 3 * a.n; c++) a.x[c] = b.x[c] = a.x_rest[c] + 0.004 * (urand() - 0.5);
  for (int k = 0; k < 50; k++) {
    pbd_step(&a, 0.005, NULL, NULL);
    pbd_step(&b, 0.005, NULL, NULL);
  }
  CHECK(memcmp(a.x, b.x, 3 * a.n * sizeof(double)) == 0);
  CHECK(memcmp(a.tet_lambda, b.tet_lambda, a.ntets * sizeof(double)) == 0);
  pbd_destroy(&a);
  pbd_destroy(&b);
}

/* Optional argument: run only the parts whose name contains it. */
int main(int argc, char **argv) {
  const char *only = argc > 1 ? argv[1] : "";
#define PART(name, call)                                                                                               \
  if (strstr(name, only)) call
  PART("gradients", test_gradients());
  PART("tet_xpbd", test_single_tet(PBD_MODE_XPBD));
  PART("tet_pbd", test_single_tet(PBD_MODE_PBD));
  PART("bar_xpbd", test_bar_recovery(PBD_MODE_XPBD));
  PART("bar_pbd", test_bar_recovery(PBD_MODE_PBD));
  PART("cantilever", test_cantilever());
  PART("chain", test_mass_ratio_chain());
  PART("order", test_order());
  PART("rollback", test_rollback());
  PART("model", test_model());
#undef PART
  return check_report("test_pbd");
}
