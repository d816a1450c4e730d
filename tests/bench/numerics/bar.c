/* SPDX-License-Identifier: Apache-2.0 */
/* bar: see bar.h. */
#include "bar.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "physics/mass_spring.h"

static int cmp_edge(const void *a, const void *b) {
  const uint32_t *p = a, *q = b;
  if (p[0] != q[0]) return p[0] < q[0] ? -1 : 1;
  return (p[1] > q[1]) - (p[1] < q[1]);
}

int bar_init(bar_t *b, size_t nx, size_t ny, size_t nz, double h, verr_t *err) {
  memset(b, 0, sizeof *b);
  b->nx = nx, b->ny = ny, b->nz = nz, b->h = h;
  if (tet_mesh_box_grid(nx, ny, nz, h, &b->tm, err)) return -1;
  size_t nt = b->tm.ntets;
  b->edges = malloc(12 * nt * sizeof *b->edges);
  b->tet_rest = malloc(nt * sizeof *b->tet_rest);
  if (!b->edges || !b->tet_rest) {
    bar_free(b);
    return verr_set(err, "bar: out of memory");
  }
  static const int E[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  for (size_t t = 0; t < nt; t++) {
    const uint32_t *q = b->tm.tets + 4 * t;
    for (int e = 0; e < 6; e++) {
      uint32_t i = q[E[e][0]], j = q[E[e][1]];
      b->edges[12 * t + 2 * e] = i < j ? i : j;
      b->edges[12 * t + 2 * e + 1] = i < j ? j : i;
    }
    b->tet_rest[t] = tet_volume(&b->tm, b->tm.x, t);
  }
  qsort(b->edges, 6 * nt, 2 * sizeof *b->edges, cmp_edge);
  size_t m = 0;
  for (size_t e = 0; e < 6 * nt; e++)
    if (!m || cmp_edge(b->edges + 2 * e, b->edges + 2 * (m - 1))) {
      b->edges[2 * m] = b->edges[2 * e];
      b->edges[2 * m + 1] = b->edges[2 * e + 1];
      m++;
    }
  b->nedges = m;
  b->edge_rest = malloc(m * sizeof *b->edge_rest);
  if (!b->edge_rest) {
    bar_free(b);
    return verr_set(err, "bar: out of memory");
  }
  for (size_t e = 0; e < m; e++) {
    const double *p = b->tm.x + 3 * (size_t)b->edges[2 * e], *q = b->tm.x + 3 * (size_t)b->edges[2 * e + 1];
    b->edge_rest[e] = sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
  }
  b->mass = BAR_DENSITY * (double)(nx - 1) * (double)(ny - 1) * (double)(nz - 1) * h * h * h;
  b->diag = bbox_diag(b->tm.x, b->tm.nnodes);
  b->tip = (nx - 1) + nx * ((ny / 2) + ny * (nz / 2));
  return 0;
}

void bar_free(bar_t *b) {
  tet_mesh_free(&b->tm);
  free(b->edges);
  free(b->edge_rest);
  free(b->tet_rest);
  memset(b, 0, sizeof *b);
}

static void fix_root(const bar_t *b, double *inv_mass, size_t n) {
  for (size_t i = 0; i < n; i++)
    if (b->tm.x[3 * i] < 0.5 * b->h) inv_mass[i] = 0;
}

static double ms_energy_cb(void *owner) { return mass_spring_energy(owner); }
static void ms_free_cb(void *owner) {
  mass_spring_destroy(owner);
  free(owner);
}

sim_t *bar_mass_spring(const bar_t *b, integrator_kind_t kind, int substeps, double k, double c_ground,
                       const double g[3], const double *x0, double cg_tol, verr_t *err) {
  mass_spring_t *ms = calloc(1, sizeof *ms);
  if (!ms) return verr_set(err, "out of memory"), NULL;
  ms_params_t p = {.mass = b->mass, .stiffness = k, .home_damping = c_ground, .gravity = {g[0], g[1], g[2]}};
  if (mass_spring_create_tets(ms, &b->tm, &p, err)) {
    free(ms);
    return NULL;
  }
  fix_root(b, ms->inv_mass, ms->n);
  /* Conjugate gradients need a definite K (mass_spring.h): the product sets
   * this for implicit Euler, and so do we. */
  ms->definite_jacobian = kind == INT_IMPLICIT_EULER;
  if (x0) memcpy(ms->x, x0, 3 * ms->n * sizeof(double));
  return sim_fs(&ms->fs, kind, substeps, cg_tol, 200, ms_energy_cb, ms_free_cb, ms, err);
}

sim_t *tets_mass_spring(const tet_mesh_t *tm, integrator_kind_t kind, verr_t *err) {
  mass_spring_t *ms = calloc(1, sizeof *ms);
  if (!ms) return verr_set(err, "out of memory"), NULL;
  ms_params_t p = {.mass = 0.1, .stiffness = 30, .damping = 0.02, .home_stiffness = 30, .home_damping = 0.005};
  if (mass_spring_create_tets(ms, tm, &p, err)) {
    free(ms);
    return NULL;
  }
  ms->definite_jacobian = kind == INT_IMPLICIT_EULER;
  return sim_fs(&ms->fs, kind, 1, 1e-3, 200, ms_energy_cb, ms_free_cb, ms, err);
}

#ifdef NUMERICS_HAVE_PBD
sim_t *tets_xpbd(const tet_mesh_t *tm, int iterations, verr_t *err) {
  pbd_t *s = calloc(1, sizeof *s);
  if (!s) return verr_set(err, "out of memory"), NULL;
  pbd_params_t p = {.mode = PBD_MODE_XPBD,
                    .mass = 0.1,
                    .distance_stiffness = 1,
                    .volume_stiffness = 1,
                    .distance_compliance = 1e-4,
                    .volume_compliance = 1e-6,
                    .home_stiffness = 30,
                    .damping = 0.005,
                    .substeps = 1,
                    .iterations = iterations,
                    .stiffness_correction = 1};
  if (pbd_create(s, tm->nnodes, tm->x, tm->ntets, tm->tets, &p, err)) {
    free(s);
    return NULL;
  }
  return sim_pbd(s, err);
}

sim_t *bar_pbd(const bar_t *b, int xpbd, int substeps, int iterations, double k, double damping, const double g[3],
               const double *x0, verr_t *err) {
  pbd_t *s = calloc(1, sizeof *s);
  if (!s) return verr_set(err, "out of memory"), NULL;
  pbd_params_t p = {.mode = xpbd ? PBD_MODE_XPBD : PBD_MODE_PBD,
                    .mass = b->mass,
                    .distance_stiffness = 1,
                    .volume_stiffness = 1,
                    .distance_compliance = 1 / k,
                    .volume_compliance = BAR_VOLUME_OFF,
                    .home_stiffness = 0,
                    .damping = damping,
                    .gravity = {g[0], g[1], g[2]},
                    .substeps = substeps,
                    .iterations = iterations,
                    .stiffness_correction = 1};
  if (pbd_create(s, b->tm.nnodes, b->tm.x, b->tm.ntets, b->tm.tets, &p, err)) {
    free(s);
    return NULL;
  }
  for (size_t i = 0; i < s->n; i++)
    if (b->tm.x[3 * i] < 0.5 * b->h) pbd_fix_node(s, i);
  if (x0) memcpy(s->x, x0, 3 * s->n * sizeof(double));
  return sim_pbd(s, err);
}
#endif

void bar_measures(const bar_t *b, const double *x, double *min_ratio, double *inverted, double *worst_vol,
                  double *max_strain) {
  double mn = INFINITY, worst = 0, inv = 0, strain = 0;
  for (size_t t = 0; t < b->tm.ntets; t++) {
    double r = tet_volume(&b->tm, x, t) / b->tet_rest[t];
    mn = fmin(mn, r);
    worst = fmax(worst, fabs(r - 1));
    inv += r <= 0;
  }
  for (size_t e = 0; e < b->nedges; e++) {
    const double *p = x + 3 * (size_t)b->edges[2 * e], *q = x + 3 * (size_t)b->edges[2 * e + 1];
    double L = sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
    strain = fmax(strain, fabs(L / b->edge_rest[e] - 1));
  }
  *min_ratio = mn;
  *inverted = inv;
  *worst_vol = worst;
  *max_strain = strain;
}

double bar_omega_max(const bar_t *b, double k) {
  verr_t err;
  mass_spring_t ms;
  ms_params_t p = {.mass = b->mass, .stiffness = k};
  if (mass_spring_create_tets(&ms, &b->tm, &p, &err)) return NAN;
  fix_root(b, ms.inv_mass, ms.n);
  double lk = NAN, lc;
  if (mass_spring_eigen_bounds(&ms, 0, &lk, &lc)) lk = NAN;
  mass_spring_destroy(&ms);
  return sqrt(lk);
}
