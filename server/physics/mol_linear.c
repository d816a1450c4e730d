/* SPDX-License-Identifier: Apache-2.0 */
#include "physics/mol_linear.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define STRIDE 15

int mol_linear_reserve(mol_linear_t *L, size_t ntris, verr_t *err) {
  if (ntris <= L->cap) return 0;
  double *t = realloc(L->tri, (ntris ? ntris : 1) * STRIDE * sizeof(double));
  if (!t) return verr_set(err, "molecular: out of memory for the linear cache of %zu triangles", ntris);
  L->tri = t;
  L->cap = ntris;
  return 0;
}

void mol_linear_free(mol_linear_t *L) {
  free(L->tri);
  memset(L, 0, sizeof *L);
}

typedef struct d3 {
  double x, y, z;
} d3;
static inline d3 at(const double *p, uint32_t i) {
  return (d3){p[3 * (size_t)i], p[3 * (size_t)i + 1], p[3 * (size_t)i + 2]};
}
static inline d3 sub(d3 a, d3 b) { return (d3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static inline double dot(d3 a, d3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline d3 comb(double a, d3 p, double b, d3 q) {
  return (d3){a * p.x + b * q.x, a * p.y + b * q.y, a * p.z + b * q.z};
}
static inline void acc(double *p, uint32_t i, double s, d3 a) {
  p[3 * (size_t)i] += s * a.x;
  p[3 * (size_t)i + 1] += s * a.y;
  p[3 * (size_t)i + 2] += s * a.z;
}
static inline void acc_sq(double *p, uint32_t i, double s, d3 a) {
  p[3 * (size_t)i] += s * a.x * a.x;
  p[3 * (size_t)i + 1] += s * a.y * a.y;
  p[3 * (size_t)i + 2] += s * a.z * a.z;
}

/* out += sign (a K + b C_bond) y over the triangles, from the cache: with
 * f_k = y_{k+1} - y_k, ld_k = u_k . f_k is the rate of bond k and, for
 * corner k (a = e_k, b = -e_{k+2}), the cosine's rate is
 *   cd_k = (ub . fa - c ld_a) / la + (ua . fb - c ld_b) / lb
 * with ua = u_k, ub = -u_{k+2}, fa = f_k, fb = -f_{k+2}. Q (eq. 6, 9, 11)
 * turns the rates into generalised forces gl (per bond) and gc (per
 * corner), which go back along the same gradients (molecular.c, corner). */
static void gn_apply(const mol_linear_t *L, const molecular_t *m, double a, double b, double sign, const double *y,
                     double *out) {
  const mol_params_t *p = &m->p;
  const double kb = a * p->bond_k + b * p->bond_damping, kt = a * p->angle_k, ksb = a * p->stretch_bend_k;
  const int angles = kt != 0 || ksb != 0;
  for (size_t t = 0; t < m->ntris; t++) {
    const mol_tri_t *tr = &m->tris[t];
    const double *c = L->tri + STRIDE * t;
    const uint32_t i0 = tr->v[0], i1 = tr->v[1], i2 = tr->v[2];
    const d3 u[3] = {{c[0], c[1], c[2]}, {c[3], c[4], c[5]}, {c[6], c[7], c[8]}};
    const double il[3] = {c[9], c[10], c[11]}, cs[3] = {c[12], c[13], c[14]};
    const d3 y0 = at(y, i0), y1 = at(y, i1), y2 = at(y, i2);
    const d3 f[3] = {sub(y1, y0), sub(y2, y1), sub(y0, y2)};
    const double ld[3] = {dot(u[0], f[0]), dot(u[1], f[1]), dot(u[2], f[2])};
    double gl[3] = {0, 0, 0};
    const uint32_t owns = tr->owns;
    for (int k = 0; k < 3; k++)
      if (owns & (1u << k)) gl[k] = kb * ld[k];
    /* dE/de_k = gl_k u_k + (corner terms) */
    d3 G[3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    if (angles)
      for (int k = 0; k < 3; k++) {
        const int j = (k + 2) % 3; /* corner k: bonds k (a) and j (b = -e_j) */
        const double ubfa = -dot(u[j], f[k]), uafb = -dot(u[k], f[j]);
        const double cd = il[k] * (ubfa - cs[k] * ld[k]) + il[j] * (uafb - cs[k] * ld[j]);
        const double gc = kt * cd + ksb * (ld[k] + ld[j]), gr = ksb * cd;
        gl[k] += gr;
        gl[j] += gr;
        /* dc/de_k = (-u_j - c u_k) / l_k, dc/de_j = -(u_k + c u_j) / l_j */
        const d3 dk = comb(-gc * il[k], u[j], -gc * il[k] * cs[k], u[k]);
        const d3 dj = comb(-gc * il[j], u[k], -gc * il[j] * cs[k], u[j]);
        G[k] = (d3){G[k].x + dk.x, G[k].y + dk.y, G[k].z + dk.z};
        G[j] = (d3){G[j].x + dj.x, G[j].y + dj.y, G[j].z + dj.z};
      }
    for (int k = 0; k < 3; k++) G[k] = (d3){G[k].x + gl[k] * u[k].x, G[k].y + gl[k] * u[k].y, G[k].z + gl[k] * u[k].z};
    /* The gradient at vertex k is G_{k+2} - G_k. */
    acc(out, i0, sign, sub(G[2], G[0]));
    acc(out, i1, sign, sub(G[0], G[1]));
    acc(out, i2, sign, sub(G[1], G[2]));
  }
}

void mol_linear_linearize(mol_linear_t *L, const molecular_t *m, double h, double *rhs, double *diag) {
  const mol_params_t *p = &m->p;
  const double *x = m->x, eps2 = m->eps2;
  const size_t n3 = 3 * m->n;
  L->h = h;
  /* The cache and the diagonal in one pass over the triangles. */
  const double kb = h * h * p->bond_k + h * p->bond_damping, kt = h * h * p->angle_k;
  const double dhome = h * h * p->home_stiffness + h * p->home_damping;
  for (size_t c = 0; c < n3; c++) diag[c] = dhome;
  for (size_t t = 0; t < m->ntris; t++) {
    const mol_tri_t *tr = &m->tris[t];
    double *c = L->tri + STRIDE * t;
    const uint32_t v[3] = {tr->v[0], tr->v[1], tr->v[2]};
    const d3 x0 = at(x, v[0]), x1 = at(x, v[1]), x2 = at(x, v[2]);
    const d3 e[3] = {sub(x1, x0), sub(x2, x1), sub(x0, x2)};
    const double l[3] = {sqrt(dot(e[0], e[0]) + eps2), sqrt(dot(e[1], e[1]) + eps2), sqrt(dot(e[2], e[2]) + eps2)};
    const double inv = 1.0 / (l[0] * l[1] * l[2]);
    const double il[3] = {l[1] * l[2] * inv, l[0] * l[2] * inv, l[0] * l[1] * inv};
    d3 u[3];
    for (int k = 0; k < 3; k++) {
      u[k] = comb(il[k], e[k], 0, e[k]);
      c[3 * k] = u[k].x;
      c[3 * k + 1] = u[k].y;
      c[3 * k + 2] = u[k].z;
      c[9 + k] = il[k];
    }
    for (int k = 0; k < 3; k++) {
      const int j = (k + 2) % 3;
      c[12 + k] = -dot(e[k], e[j]) * il[k] * il[j];
    }
    for (int k = 0; k < 3; k++)
      if (tr->owns & (1u << k)) {
        acc_sq(diag, v[k], kb, u[k]);
        acc_sq(diag, v[(k + 1) % 3], kb, u[k]);
      }
    if (kt != 0)
      for (int k = 0; k < 3; k++) {
        /* corner k at vertex v[k]: dc/dx_{k+1} = ga, dc/dx_{k+2} = gb, dc/dx_k = -(ga + gb) */
        const int j = (k + 2) % 3;
        const double cs = c[12 + k];
        const d3 ga = comb(-il[k], u[j], -il[k] * cs, u[k]);
        const d3 gb = comb(il[j], u[k], il[j] * cs, u[j]);
        acc_sq(diag, v[(k + 1) % 3], kt, ga);
        acc_sq(diag, v[j], kt, gb);
        acc_sq(diag, v[k], kt, (d3){ga.x + gb.x, ga.y + gb.y, ga.z + gb.z});
      }
  }
  /* rhs = h F - h^2 K v */
  molecular_forces(m, x, m->v, rhs);
  for (size_t c = 0; c < n3; c++) rhs[c] = h * rhs[c] - h * h * p->home_stiffness * m->v[c];
  gn_apply(L, m, h * h, 0, -1, m->v, rhs);
}

void mol_linear_mul(const mol_linear_t *L, const molecular_t *m, const double *y, double *out) {
  const mol_params_t *p = &m->p;
  const double h = L->h, dhome = h * h * p->home_stiffness + h * p->home_damping;
  for (size_t i = 0; i < m->n; i++) {
    const double d = m->mass[i] + dhome;
    for (int k = 0; k < 3; k++) out[3 * i + k] = d * y[3 * i + k];
  }
  gn_apply(L, m, h * h, h, 1, y, out);
}
