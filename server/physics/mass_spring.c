#include "mass_spring.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "vmath.h"

/* Edge set from triangles: sort (min,max) pairs and drop repeats. O(T log T),
 * no hash table needed for a one-off build. */
static int cmp_edge(const void *a, const void *b) {
  const uint32_t *x = a, *y = b;
  if (x[0] != y[0]) return x[0] < y[0] ? -1 : 1;
  return (x[1] > y[1]) - (x[1] < y[1]);
}

int mass_spring_create(mass_spring_t *ms, const mesh_t *s, const ms_params_t *p, verr_t *err) {
  memset(ms, 0, sizeof *ms);
  if (!(p->mass > 0) || !(p->stiffness >= 0) || !(p->damping >= 0) || !(p->home_stiffness >= 0) ||
      !(p->home_damping >= 0) || !v3_isfinite(p->gravity))
    return verr_set(err, "mass-spring: mass must be > 0 and stiffness/damping >= 0");
  size_t n = s->nverts;
  ms->n = n;
  ms->p = *p;
  ms->x = calloc(3 * n, sizeof(double));
  ms->v = calloc(3 * n, sizeof(double));
  ms->x_rest = calloc(3 * n, sizeof(double));
  ms->f = calloc(3 * n, sizeof(double));
  ms->f_ext = calloc(3 * n, sizeof(double));
  ms->x_prev = calloc(3 * n, sizeof(double));
  ms->v_prev = calloc(3 * n, sizeof(double));
  ms->inv_mass = calloc(n, sizeof(double));
  ms->mass = calloc(n, sizeof(double));
  uint32_t *edges = malloc(s->ntris * 6 * sizeof(uint32_t) + 1);
  if (!ms->x || !ms->v || !ms->x_rest || !ms->f || !ms->f_ext || !ms->x_prev || !ms->v_prev || !ms->inv_mass ||
      !ms->mass || !edges) {
    free(edges);
    mass_spring_destroy(ms);
    return verr_set(err, "mass-spring: out of memory for %zu vertices", n);
  }
  memcpy(ms->x, s->pos, 3 * n * sizeof(double));
  memcpy(ms->x_rest, s->pos, 3 * n * sizeof(double));

  /* Lumped masses are uniform (seed 000 eq. 1: equal point masses). Area
   * weighting would give the tiny triangles of real meshes tiny masses and
   * with them a much smaller stable step. */
  double total_area = 0;
  for (size_t t = 0; t < s->ntris; t++) {
    const uint32_t *f = s->tris + 3 * t;
    double e1[3], e2[3], c[3];
    v3_sub(e1, s->pos + 3 * f[1], s->pos + 3 * f[0]);
    v3_sub(e2, s->pos + 3 * f[2], s->pos + 3 * f[0]);
    v3_cross(c, e1, e2);
    total_area += 0.5 * v3_norm(c);
    for (int k = 0; k < 3; k++) {
      uint32_t i = f[k], j = f[(k + 1) % 3];
      edges[6 * t + 2 * k] = i < j ? i : j;
      edges[6 * t + 2 * k + 1] = i < j ? j : i;
    }
  }
  if (!(total_area > 0)) {
    free(edges);
    mass_spring_destroy(ms);
    return verr_set(err, "mass-spring: mesh has zero surface area");
  }
  for (size_t i = 0; i < n; i++) {
    ms->mass[i] = p->mass / (double)n;
    ms->inv_mass[i] = 1.0 / ms->mass[i];
  }
  size_t ne = s->ntris * 3;
  qsort(edges, ne, 2 * sizeof(uint32_t), cmp_edge);
  size_t unique = 0;
  for (size_t e = 0; e < ne; e++)
    if (e == 0 || cmp_edge(edges + 2 * e, edges + 2 * (e - 1)) != 0) unique++;
  ms->springs = malloc((unique + 1) * sizeof(ms_spring_t));
  if (!ms->springs) {
    free(edges);
    mass_spring_destroy(ms);
    return verr_set(err, "mass-spring: out of memory for springs");
  }
  for (size_t e = 0; e < ne; e++) {
    if (e > 0 && cmp_edge(edges + 2 * e, edges + 2 * (e - 1)) == 0) continue;
    uint32_t i = edges[2 * e], j = edges[2 * e + 1];
    if (i == j) continue;
    ms_spring_t *sp = &ms->springs[ms->nsprings++];
    sp->i = i;
    sp->j = j;
    sp->rest = v3_dist(s->pos + 3 * i, s->pos + 3 * j);
  }
  free(edges);
  return 0;
}

void mass_spring_destroy(mass_spring_t *ms) {
  free(ms->x);
  free(ms->v);
  free(ms->x_rest);
  free(ms->f);
  free(ms->f_ext);
  free(ms->x_prev);
  free(ms->v_prev);
  free(ms->inv_mass);
  free(ms->mass);
  free(ms->springs);
  memset(ms, 0, sizeof *ms);
}

size_t mass_spring_fix_below(mass_spring_t *ms, double z) {
  size_t count = 0;
  for (size_t i = 0; i < ms->n; i++)
    if (ms->x_rest[3 * i + 2] < z) {
      ms->inv_mass[i] = 0;
      count++;
    }
  return count;
}

/* y = M^-1 (A x) where A is the rest-state stiffness (or damping) matrix:
 * per spring a u u^T block of weight `edge`, plus `home` on the diagonal.
 * Fixed vertices are removed from the system. */
static void rest_matvec(const mass_spring_t *ms, double edge, double home, const double *x, double *y) {
  for (size_t c = 0; c < 3 * ms->n; c++) y[c] = home * x[c];
  for (size_t s = 0; s < ms->nsprings; s++) {
    const ms_spring_t *sp = &ms->springs[s];
    double u[3], d[3];
    v3_sub(u, ms->x_rest + 3 * sp->j, ms->x_rest + 3 * sp->i);
    v3_normalize(u);
    v3_sub(d, x + 3 * sp->i, x + 3 * sp->j);
    double a = edge * v3_dot(u, d);
    v3_axpy(y + 3 * sp->i, u, a);
    v3_axpy(y + 3 * sp->j, u, -a);
  }
  for (size_t i = 0; i < ms->n; i++)
    for (int k = 0; k < 3; k++) y[3 * i + k] *= ms->inv_mass[i];
}

/* Largest eigenvalue of M^-1 A by power iteration (NUMERICS.md: omega_max by
 * power iteration). A is symmetric positive semi-definite and M diagonal, so
 * the eigenvalues are real and non-negative and the iteration converges from
 * a generic start. Scaled up by 2 % to cover the unconverged remainder. */
static double rest_lambda_max(const mass_spring_t *ms, double edge, double home, double *x, double *y) {
  unsigned seed = 12345;
  for (size_t c = 0; c < 3 * ms->n; c++) {
    seed = seed * 1664525u + 1013904223u;
    x[c] = ((double)(seed >> 8) / 16777216.0 - 0.5) * (ms->inv_mass[c / 3] > 0);
  }
  double lambda = 0;
  for (int it = 0; it < 200; it++) {
    double nx = 0;
    for (size_t c = 0; c < 3 * ms->n; c++) nx += x[c] * x[c];
    nx = sqrt(nx);
    if (!(nx > 0)) return 0;
    rest_matvec(ms, edge, home, x, y);
    double ny = 0;
    for (size_t c = 0; c < 3 * ms->n; c++) ny += y[c] * y[c];
    ny = sqrt(ny);
    double next = ny / nx;
    for (size_t c = 0; c < 3 * ms->n; c++) x[c] = y[c] / (ny > 0 ? ny : 1);
    if (it > 20 && fabs(next - lambda) <= 1e-4 * next) {
      lambda = next;
      break;
    }
    lambda = next;
  }
  return 1.02 * lambda;
}

double mass_spring_stable_dt(const mass_spring_t *ms) {
  double *x = malloc((3 * ms->n + 1) * sizeof(double)), *y = malloc((3 * ms->n + 1) * sizeof(double));
  if (!x || !y) {
    free(x);
    free(y);
    return 0;
  }
  double lk = rest_lambda_max(ms, ms->p.stiffness, ms->p.home_stiffness, x, y);
  double lc = rest_lambda_max(ms, ms->p.damping, ms->p.home_damping, x, y);
  free(x);
  free(y);
  if (ms->p.integrator == MS_EXPLICIT_EULER) {
    /* h <= 2 zeta / omega with zeta = lc / (2 omega): h <= lc / lk. */
    return lk > 0 ? lc / lk : INFINITY;
  }
  if (lk == 0 && lc == 0) return INFINITY;
  if (lk == 0) return 2.0 / lc;
  /* Positive root of lk h^2 + 2 lc h - 4 = 0 (the damped oscillator's
   * symplectic Euler bound, applied to the extreme modes). */
  return (-lc + sqrt(lc * lc + 4 * lk)) / lk;
}

void mass_spring_forces(const mass_spring_t *ms, const double *x, const double *v, double *f) {
  const ms_params_t *p = &ms->p;
  for (size_t i = 0; i < ms->n; i++) {
    const double *xi = x + 3 * i, *vi = v + 3 * i, *xr = ms->x_rest + 3 * i;
    double *fi = f + 3 * i;
    for (int k = 0; k < 3; k++)
      fi[k] = ms->f_ext[3 * i + k] + ms->mass[i] * p->gravity[k] - p->home_stiffness * (xi[k] - xr[k]) -
              p->home_damping * vi[k];
  }
  for (size_t s = 0; s < ms->nsprings; s++) {
    const ms_spring_t *sp = &ms->springs[s];
    double d[3], dv[3];
    v3_sub(d, x + 3 * sp->j, x + 3 * sp->i);
    double len = v3_normalize(d);
    /* A zero-length spring has no direction: it then pushes nothing, which
     * keeps forces finite when two vertices are moved onto each other. */
    if (len <= 1e-300) continue;
    v3_sub(dv, v + 3 * sp->j, v + 3 * sp->i);
    double mag = p->stiffness * (len - sp->rest) + p->damping * v3_dot(dv, d);
    v3_axpy(f + 3 * sp->i, d, mag);
    v3_axpy(f + 3 * sp->j, d, -mag);
  }
}

int mass_spring_step(mass_spring_t *ms, double h, int substeps, ms_substep_fn pre, void *ctx) {
  size_t n3 = 3 * ms->n;
  memcpy(ms->x_prev, ms->x, n3 * sizeof(double));
  memcpy(ms->v_prev, ms->v, n3 * sizeof(double));
  if (substeps < 1) substeps = 1;
  double hs = h / substeps;
  for (int s = 0; s < substeps; s++) {
    if (pre) pre(ms, ctx);
    mass_spring_forces(ms, ms->x, ms->v, ms->f);
    memset(ms->f_ext, 0, n3 * sizeof(double));
    if (ms->p.integrator == MS_EXPLICIT_EULER) {
      for (size_t i = 0; i < ms->n; i++) {
        double w = ms->inv_mass[i] * hs;
        for (int k = 0; k < 3; k++) {
          size_t c = 3 * i + k;
          ms->x[c] += hs * ms->v[c] * (w > 0);
          ms->v[c] += w * ms->f[c];
        }
      }
    } else {
      for (size_t i = 0; i < ms->n; i++) {
        double w = ms->inv_mass[i] * hs;
        for (int k = 0; k < 3; k++) {
          size_t c = 3 * i + k;
          ms->v[c] += w * ms->f[c];
          ms->x[c] += hs * ms->v[c];
        }
      }
    }
  }
  /* Summing once is cheaper than testing every coordinate: NaN or Inf
   * anywhere makes the sum non-finite. */
  double sum = 0;
  for (size_t c = 0; c < n3; c++) sum += ms->x[c] + ms->v[c];
  if (!isfinite(sum)) {
    memcpy(ms->x, ms->x_prev, n3 * sizeof(double));
    memcpy(ms->v, ms->v_prev, n3 * sizeof(double));
    return -1;
  }
  return 0;
}

double mass_spring_energy(const mass_spring_t *ms) {
  double e = 0;
  for (size_t i = 0; i < ms->n; i++) {
    e += 0.5 * ms->mass[i] * v3_dot(ms->v + 3 * i, ms->v + 3 * i);
    double d[3];
    v3_sub(d, ms->x + 3 * i, ms->x_rest + 3 * i);
    e += 0.5 * ms->p.home_stiffness * v3_dot(d, d);
    e -= ms->mass[i] * v3_dot(ms->p.gravity, ms->x + 3 * i);
  }
  for (size_t s = 0; s < ms->nsprings; s++) {
    double l = v3_dist(ms->x + 3 * ms->springs[s].i, ms->x + 3 * ms->springs[s].j) - ms->springs[s].rest;
    e += 0.5 * ms->p.stiffness * l * l;
  }
  return e;
}

double mass_spring_max_strain(const mass_spring_t *ms) {
  double m = 0;
  for (size_t s = 0; s < ms->nsprings; s++) {
    const ms_spring_t *sp = &ms->springs[s];
    if (!(sp->rest > 0)) continue;
    double e = fabs(v3_dist(ms->x + 3 * sp->i, ms->x + 3 * sp->j) / sp->rest - 1);
    if (e > m) m = e;
  }
  return m;
}
