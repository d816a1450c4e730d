/* SPDX-License-Identifier: Apache-2.0 */
/* springnet: see springnet.h. */
#include "springnet.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static void sn_forces(force_system_t *fs, const double *x, const double *v, double *f) {
  springnet_t *s = fs->ctx;
  for (size_t i = 0; i < s->n; i++)
    for (int d = 0; d < 3; d++) f[3 * i + d] = s->mass[i] * s->gravity[d];
  for (size_t e = 0; e < s->ns; e++) {
    size_t i = s->sp[2 * e], j = s->sp[2 * e + 1];
    double d[3], L2 = 0;
    for (int a = 0; a < 3; a++) d[a] = x[3 * j + a] - x[3 * i + a], L2 += d[a] * d[a];
    double L = sqrt(L2);
    if (!(L > 1e-300)) continue; /* coincident nodes: no direction, no force */
    double u[3] = {d[0] / L, d[1] / L, d[2] / L};
    double dv = 0;
    for (int a = 0; a < 3; a++) dv += (v[3 * j + a] - v[3 * i + a]) * u[a];
    double mag = s->k[e] * (L - s->rest[e]) + s->c[e] * dv;
    for (int a = 0; a < 3; a++) {
      f[3 * i + a] += mag * u[a];
      f[3 * j + a] -= mag * u[a];
    }
  }
}

/* out = (a K + b C) y with K = -dF/dx, C = -dF/dv. Per spring the stiffness
 * block is k [u u^T + (1 - L0/L)(I - u u^T)]; the transverse (geometric)
 * part is clamped at zero under compression so K stays positive
 * semi-definite, which conjugate gradients in implicit Euler need. */
static void sn_stiffness_mul(force_system_t *fs, const double *x, double a, double b, const double *y, double *out) {
  springnet_t *s = fs->ctx;
  memset(out, 0, 3 * s->n * sizeof *out);
  for (size_t e = 0; e < s->ns; e++) {
    size_t i = s->sp[2 * e], j = s->sp[2 * e + 1];
    double d[3], L2 = 0;
    for (int q = 0; q < 3; q++) d[q] = x[3 * j + q] - x[3 * i + q], L2 += d[q] * d[q];
    double L = sqrt(L2);
    if (!(L > 1e-300)) continue;
    double u[3] = {d[0] / L, d[1] / L, d[2] / L};
    double dy[3], du = 0;
    for (int q = 0; q < 3; q++) dy[q] = y[3 * j + q] - y[3 * i + q], du += dy[q] * u[q];
    double geo = 1 - s->rest[e] / L;
    if (geo < 0) geo = 0;
    double ka = a * s->k[e], cb = b * s->c[e];
    for (int q = 0; q < 3; q++) {
      double r = ka * (du * u[q] + geo * (dy[q] - du * u[q])) + cb * du * u[q];
      out[3 * j + q] += r;
      out[3 * i + q] -= r;
    }
  }
}

int springnet_alloc(springnet_t *s, size_t n, size_t ns, verr_t *err) {
  memset(s, 0, sizeof *s);
  s->n = n;
  s->ns = ns;
  s->x = calloc(3 * n, sizeof *s->x);
  s->v = calloc(3 * n, sizeof *s->v);
  s->x0 = calloc(3 * n, sizeof *s->x0);
  s->mass = calloc(n, sizeof *s->mass);
  s->inv_mass = calloc(n, sizeof *s->inv_mass);
  s->sp = calloc(2 * (ns ? ns : 1), sizeof *s->sp);
  s->rest = calloc(ns ? ns : 1, sizeof *s->rest);
  s->k = calloc(ns ? ns : 1, sizeof *s->k);
  s->c = calloc(ns ? ns : 1, sizeof *s->c);
  if (!s->x || !s->v || !s->x0 || !s->mass || !s->inv_mass || !s->sp || !s->rest || !s->k || !s->c) {
    springnet_free(s);
    return verr_set(err, "springnet: out of memory for %zu nodes", n);
  }
  for (size_t i = 0; i < n; i++) s->mass[i] = s->inv_mass[i] = 1;
  s->fs = (force_system_t){.n = n,
                           .x = s->x,
                           .v = s->v,
                           .mass = s->mass,
                           .inv_mass = s->inv_mass,
                           .forces = sn_forces,
                           .stiffness_mul = sn_stiffness_mul,
                           .pre_substep = NULL,
                           .ctx = s};
  return 0;
}

void springnet_free(springnet_t *s) {
  free(s->x);
  free(s->v);
  free(s->x0);
  free(s->mass);
  free(s->inv_mass);
  free(s->sp);
  free(s->rest);
  free(s->k);
  free(s->c);
  memset(s, 0, sizeof *s);
}

void springnet_set_spring(springnet_t *s, size_t e, uint32_t i, uint32_t j, double k, double c) {
  s->sp[2 * e] = i;
  s->sp[2 * e + 1] = j;
  double d2 = 0;
  for (int a = 0; a < 3; a++) d2 += (s->x[3 * (size_t)j + a] - s->x[3 * (size_t)i + a]) * (s->x[3 * (size_t)j + a] - s->x[3 * (size_t)i + a]);
  s->rest[e] = sqrt(d2);
  s->k[e] = k;
  s->c[e] = c;
}

void springnet_mark_initial(springnet_t *s) {
  memcpy(s->x0, s->x, 3 * s->n * sizeof *s->x);
  memset(s->v, 0, 3 * s->n * sizeof *s->v);
}

void springnet_reset(springnet_t *s) {
  memcpy(s->x, s->x0, 3 * s->n * sizeof *s->x);
  memset(s->v, 0, 3 * s->n * sizeof *s->v);
}

double springnet_energy(const springnet_t *s) {
  double e = 0;
  for (size_t i = 0; i < s->n; i++) {
    const double *v = s->v + 3 * i, *x = s->x + 3 * i;
    if (s->inv_mass[i] > 0) e += 0.5 * s->mass[i] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    /* Fixed nodes do not move, so their gravity term is a constant we drop. */
    if (s->inv_mass[i] > 0)
      e -= s->mass[i] * (s->gravity[0] * x[0] + s->gravity[1] * x[1] + s->gravity[2] * (x[2] - s->z_ref));
  }
  for (size_t k = 0; k < s->ns; k++) {
    size_t i = s->sp[2 * k], j = s->sp[2 * k + 1];
    double d2 = 0;
    for (int a = 0; a < 3; a++) d2 += (s->x[3 * j + a] - s->x[3 * i + a]) * (s->x[3 * j + a] - s->x[3 * i + a]);
    double dl = sqrt(d2) - s->rest[k];
    e += 0.5 * s->k[k] * dl * dl;
  }
  return e;
}

double springnet_lambda_max(springnet_t *s, int iters) {
  size_t n3 = 3 * s->n;
  double *y = malloc(n3 * sizeof *y), *z = malloc(n3 * sizeof *z);
  if (!y || !z) {
    free(y);
    free(z);
    return NAN;
  }
  /* A fixed pseudo-random start so runs are repeatable; it has a component
   * along every mode with probability one. */
  uint64_t r = 0x9E3779B97F4A7C15ull;
  for (size_t i = 0; i < n3; i++) {
    r ^= r << 13, r ^= r >> 7, r ^= r << 17;
    y[i] = s->inv_mass[i / 3] > 0 ? (double)(r >> 11) / 9007199254740992.0 - 0.5 : 0;
  }
  double lambda = 0;
  for (int it = 0; it < iters; it++) {
    double ny = 0;
    for (size_t i = 0; i < n3; i++) ny += y[i] * y[i];
    ny = sqrt(ny);
    if (!(ny > 0)) break;
    for (size_t i = 0; i < n3; i++) y[i] /= ny;
    sn_stiffness_mul(&s->fs, s->x, 1, 0, y, z);
    /* M^-1 K restricted to the free nodes (a fixed node's row and column
     * are removed, as the integrators hold it). y has unit length, so |z|
     * tends to the dominant eigenvalue as y tends to its eigenvector. */
    double nz = 0;
    for (size_t i = 0; i < n3; i++) {
      z[i] *= s->inv_mass[i / 3];
      nz += z[i] * z[i];
    }
    lambda = sqrt(nz);
    memcpy(y, z, n3 * sizeof *y);
  }
  free(y);
  free(z);
  return lambda;
}
