/* SPDX-License-Identifier: Apache-2.0 */
/* ms_linear: the fused force and Jacobian pass of ms_linear.h. */
#include "physics/ms_linear.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* As mass_spring.c: below this length a spring has no direction. */
#define MSL_TINY 1e-300

int ms_linear_reserve(ms_linear_t *L, size_t nsprings, verr_t *err) {
  if (nsprings <= L->spring_cap && L->blk) return 0;
  if (nsprings > ((size_t)-1) / (5 * sizeof(double)) - 1) return verr_set(err, "implicit_pcg: too many springs");
  double *b = realloc(L->blk, 5 * nsprings * sizeof(double) + 1);
  if (!b) return verr_set(err, "implicit_pcg: out of memory for %zu springs", nsprings);
  L->blk = b;
  L->spring_cap = nsprings;
  return 0;
}

void ms_linear_free(ms_linear_t *L) {
  free(L->blk);
  memset(L, 0, sizeof *L);
}

void ms_linear_rhs(ms_linear_t *L, const mass_spring_t *ms, double h, double *restrict rhs, double *restrict diag) {
  const size_t n = ms->n, ns = ms->nsprings;
  const double *restrict x = ms->x, *restrict v = ms->v, *restrict xr = ms->x_rest, *restrict fext = ms->f_ext;
  const double *restrict mass = ms->mass, *restrict fres = ms->f_res, *restrict kscale = ms->k_scale;
  const double g0 = ms->p.gravity[0], g1 = ms->p.gravity[1], g2 = ms->p.gravity[2];
  const double hk = ms->p.home_stiffness, hc = ms->p.home_damping, h2 = h * h;
  const double cdamp = ms->p.damping * ms->damping_scale, cjac = h * ms->p.damping;
  const double stiffness = ms->p.stiffness;
  L->home = h2 * hk + h * hc;
  /* Node terms: h (f_ext + m g - hk (x - x_rest) - hc v + f_res) - h^2 hk v. */
  const double home = L->home, hv = h * hc + h2 * hk;
  for (size_t i = 0; i < n; i++) {
    const size_t c = 3 * i;
    const double mh = h * mass[i];
    rhs[c] = h * (fext[c] - hk * (x[c] - xr[c])) + mh * g0 - hv * v[c];
    rhs[c + 1] = h * (fext[c + 1] - hk * (x[c + 1] - xr[c + 1])) + mh * g1 - hv * v[c + 1];
    rhs[c + 2] = h * (fext[c + 2] - hk * (x[c + 2] - xr[c + 2])) + mh * g2 - hv * v[c + 2];
    diag[c] = diag[c + 1] = diag[c + 2] = home;
  }
  if (fres)
    for (size_t c = 0; c < 3 * n; c++) rhs[c] += h * fres[c];
  /* Springs by runs of equal i (as the force loop in mass_spring.c): node
   * i's rhs and diagonal stay in registers over its run. */
  const ms_spring_t *restrict sp = ms->springs;
  double *restrict blk = L->blk;
  size_t s = 0;
  while (s < ns) {
    const uint32_t i = sp[s].i;
    const double xi0 = x[3 * i], xi1 = x[3 * i + 1], xi2 = x[3 * i + 2];
    const double vi0 = v[3 * i], vi1 = v[3 * i + 1], vi2 = v[3 * i + 2];
    double ri0 = 0, ri1 = 0, ri2 = 0, di0 = 0, di1 = 0, di2 = 0;
    for (; s < ns && sp[s].i == i; s++) {
      const uint32_t j = sp[s].j;
      double *bs = blk + 5 * s;
      const double d0 = x[3 * j] - xi0, d1 = x[3 * j + 1] - xi1, d2 = x[3 * j + 2] - xi2;
      const double len = sqrt(d0 * d0 + d1 * d1 + d2 * d2);
      if (len <= MSL_TINY) { /* no direction: no force, no stiffness */
        bs[0] = bs[1] = bs[2] = bs[3] = bs[4] = 0;
        continue;
      }
      const double inv = 1.0 / len, u0 = d0 * inv, u1 = d1 * inv, u2 = d2 * inv;
      const double w0 = vi0 - v[3 * j], w1 = vi1 - v[3 * j + 1], w2 = vi2 - v[3 * j + 2];
      const double wu = w0 * u0 + w1 * u1 + w2 * u2;
      const double k = kscale ? stiffness * kscale[s] : stiffness;
      /* Force on i: (k (len - rest) + c (v_j - v_i) . u) u. */
      const double mag = k * (len - sp[s].rest) - cdamp * wu;
      /* K block: ak I + bk u u^T, geometric part clamped at 0 (definite). */
      double ak = k * (1 - sp[s].rest * inv);
      if (ak < 0) ak = 0;
      const double bk = k - ak;
      /* e = h f_i - h^2 K (v_i - v_j) */
      const double cu = h * mag - h2 * bk * wu, hak = h2 * ak;
      const double e0 = cu * u0 - hak * w0, e1 = cu * u1 - hak * w1, e2 = cu * u2 - hak * w2;
      const double beta = h2 * bk + cjac;
      bs[0] = u0;
      bs[1] = u1;
      bs[2] = u2;
      bs[3] = hak;
      bs[4] = beta;
      const double q0 = hak + beta * u0 * u0, q1 = hak + beta * u1 * u1, q2 = hak + beta * u2 * u2;
      ri0 += e0;
      ri1 += e1;
      ri2 += e2;
      di0 += q0;
      di1 += q1;
      di2 += q2;
      rhs[3 * j] -= e0;
      rhs[3 * j + 1] -= e1;
      rhs[3 * j + 2] -= e2;
      diag[3 * j] += q0;
      diag[3 * j + 1] += q1;
      diag[3 * j + 2] += q2;
    }
    rhs[3 * i] += ri0;
    rhs[3 * i + 1] += ri1;
    rhs[3 * i + 2] += ri2;
    diag[3 * i] += di0;
    diag[3 * i + 1] += di1;
    diag[3 * i + 2] += di2;
  }
}

void ms_linear_mul(const ms_linear_t *L, const mass_spring_t *ms, const double *restrict y, double *restrict out) {
  const size_t n = ms->n, ns = ms->nsprings;
  const double home = L->home, *restrict mass = ms->mass;
  for (size_t i = 0; i < n; i++) {
    const double d = home + mass[i];
    out[3 * i] = d * y[3 * i];
    out[3 * i + 1] = d * y[3 * i + 1];
    out[3 * i + 2] = d * y[3 * i + 2];
  }
  /* Walked by runs of equal i, as the force loop (mass_spring.c): out_i
   * stays in registers over its run. */
  const ms_spring_t *restrict sp = ms->springs;
  const double *restrict blk = L->blk;
  size_t s = 0;
  while (s < ns) {
    const uint32_t i = sp[s].i;
    const double yi0 = y[3 * i], yi1 = y[3 * i + 1], yi2 = y[3 * i + 2];
    double oi0 = 0, oi1 = 0, oi2 = 0;
    for (; s < ns && sp[s].i == i; s++) {
      const uint32_t j = sp[s].j;
      const double *bs = blk + 5 * s;
      const double w0 = yi0 - y[3 * j], w1 = yi1 - y[3 * j + 1], w2 = yi2 - y[3 * j + 2];
      const double cu = bs[4] * (w0 * bs[0] + w1 * bs[1] + w2 * bs[2]);
      const double t0 = bs[3] * w0 + cu * bs[0], t1 = bs[3] * w1 + cu * bs[1], t2 = bs[3] * w2 + cu * bs[2];
      oi0 += t0;
      oi1 += t1;
      oi2 += t2;
      out[3 * j] -= t0;
      out[3 * j + 1] -= t1;
      out[3 * j + 2] -= t2;
    }
    out[3 * i] += oi0;
    out[3 * i + 1] += oi1;
    out[3 * i + 2] += oi2;
  }
}
