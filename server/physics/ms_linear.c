/* SPDX-License-Identifier: Apache-2.0 */
/* ms_linear: the fused force and Jacobian pass of ms_linear.h. */
#include "physics/ms_linear.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "physics/avx_rows.h"

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

/* The open run of equal i between the vector and the scalar spring loop:
 * its node (UINT32_MAX: none) and partial sums of rhs and diag. */
typedef struct msl_run {
  uint32_t cur;
  double r[3], d[3];
} msl_run_t;

static inline void msl_flush(msl_run_t *run, double *restrict rhs, double *restrict diag) {
  if (run->cur == UINT32_MAX) return;
  const size_t c = 3 * (size_t)run->cur;
  rhs[c] += run->r[0];
  rhs[c + 1] += run->r[1];
  rhs[c + 2] += run->r[2];
  diag[c] += run->d[0];
  diag[c + 1] += run->d[1];
  diag[c + 2] += run->d[2];
  run->cur = UINT32_MAX;
}

#ifdef VISCERA_HAVE_AVX_ROWS
#define MSL_HAVE_AVX2_PATH 1

/* The spring part of ms_linear_rhs four springs at a time (AVX2, chosen at
 * run time, as mass_spring.c's spring loop): each end's x and v as masked
 * row loads transposed into one vector per component, then every quantity
 * of the scalar loop below with exactly its operations in its order (mul,
 * add, one 4-wide square root and divide, no fused multiply-add; the clamp
 * keeps NaN as the scalar test does), then the blocks stored and the
 * contributions scattered in spring order with the same runs of equal i:
 * rhs, diag and the cache are bit for bit the scalar path's
 * (test_ms_linear). Returns the first spring it did not take (the scalar
 * loop finishes the last 0-3), its run left open in *run. */
__attribute__((target("avx2"))) static size_t msl_springs_avx2(ms_linear_t *L, const mass_spring_t *ms, double h,
                                                               double *restrict rhs, double *restrict diag,
                                                               msl_run_t *run) {
  const size_t ns = ms->nsprings;
  const double *restrict x = ms->x, *restrict v = ms->v, *restrict kscale = ms->k_scale;
  const ms_spring_t *restrict sp = ms->springs;
  double *restrict blk = L->blk;
  const double h2 = h * h;
  const __m256i m3 = _mm256_set_epi64x(0, -1, -1, -1);
  const __m256d one = _mm256_set1_pd(1.0), zero = _mm256_setzero_pd(), tiny = _mm256_set1_pd(MSL_TINY);
  const __m256d vh = _mm256_set1_pd(h), vh2 = _mm256_set1_pd(h2), stiff = _mm256_set1_pd(ms->p.stiffness);
  const __m256d cdamp = _mm256_set1_pd(ms->p.damping * ms->damping_scale), cjac = _mm256_set1_pd(h * ms->p.damping);
  uint32_t cur = UINT32_MAX;
  double ri0 = 0, ri1 = 0, ri2 = 0, di0 = 0, di1 = 0, di2 = 0;
  size_t s = 0;
  for (; s + 4 <= ns; s += 4) {
    __m256d dr[4], wr[4];
    for (int q = 0; q < 4; q++) {
      const size_t i3 = 3 * (size_t)sp[s + q].i, j3 = 3 * (size_t)sp[s + q].j;
      dr[q] = _mm256_sub_pd(_mm256_maskload_pd(x + j3, m3), _mm256_maskload_pd(x + i3, m3));
      wr[q] = _mm256_sub_pd(_mm256_maskload_pd(v + i3, m3), _mm256_maskload_pd(v + j3, m3));
    }
    __m256d d0, d1, d2, w0, w1, w2;
    avx_rows_transpose3(dr, &d0, &d1, &d2);
    avx_rows_transpose3(wr, &w0, &w1, &w2);
    const __m256d len = _mm256_sqrt_pd(
        _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(d0, d0), _mm256_mul_pd(d1, d1)), _mm256_mul_pd(d2, d2)));
    const int live = _mm256_movemask_pd(_mm256_cmp_pd(len, tiny, _CMP_NLE_UQ));
    const __m256d inv = _mm256_div_pd(one, len);
    const __m256d u0 = _mm256_mul_pd(d0, inv), u1 = _mm256_mul_pd(d1, inv), u2 = _mm256_mul_pd(d2, inv);
    const __m256d wu =
        _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(w0, u0), _mm256_mul_pd(w1, u1)), _mm256_mul_pd(w2, u2));
    const __m256d k = kscale ? _mm256_mul_pd(stiff, _mm256_loadu_pd(kscale + s)) : stiff;
    const __m256d rest = _mm256_set_pd(sp[s + 3].rest, sp[s + 2].rest, sp[s + 1].rest, sp[s].rest);
    const __m256d mag = _mm256_sub_pd(_mm256_mul_pd(k, _mm256_sub_pd(len, rest)), _mm256_mul_pd(cdamp, wu));
    /* max(0, ak): the second operand is returned for NaN, as the scalar clamp keeps it. */
    const __m256d ak = _mm256_max_pd(zero, _mm256_mul_pd(k, _mm256_sub_pd(one, _mm256_mul_pd(rest, inv))));
    const __m256d bk = _mm256_sub_pd(k, ak);
    const __m256d cu = _mm256_sub_pd(_mm256_mul_pd(vh, mag), _mm256_mul_pd(_mm256_mul_pd(vh2, bk), wu));
    const __m256d hak = _mm256_mul_pd(vh2, ak);
    const __m256d beta = _mm256_add_pd(_mm256_mul_pd(vh2, bk), cjac);
    double e[3][4], qd[3][4], uu[3][4], a4[4], b4[4];
    _mm256_storeu_pd(e[0], _mm256_sub_pd(_mm256_mul_pd(cu, u0), _mm256_mul_pd(hak, w0)));
    _mm256_storeu_pd(e[1], _mm256_sub_pd(_mm256_mul_pd(cu, u1), _mm256_mul_pd(hak, w1)));
    _mm256_storeu_pd(e[2], _mm256_sub_pd(_mm256_mul_pd(cu, u2), _mm256_mul_pd(hak, w2)));
    _mm256_storeu_pd(qd[0], _mm256_add_pd(hak, _mm256_mul_pd(_mm256_mul_pd(beta, u0), u0)));
    _mm256_storeu_pd(qd[1], _mm256_add_pd(hak, _mm256_mul_pd(_mm256_mul_pd(beta, u1), u1)));
    _mm256_storeu_pd(qd[2], _mm256_add_pd(hak, _mm256_mul_pd(_mm256_mul_pd(beta, u2), u2)));
    _mm256_storeu_pd(uu[0], u0);
    _mm256_storeu_pd(uu[1], u1);
    _mm256_storeu_pd(uu[2], u2);
    _mm256_storeu_pd(a4, hak);
    _mm256_storeu_pd(b4, beta);
    for (int q = 0; q < 4; q++) {
      const uint32_t i = sp[s + q].i, j = sp[s + q].j;
      double *bs = blk + 5 * (s + q);
      if (i != cur) {
        if (cur != UINT32_MAX) {
          rhs[3 * (size_t)cur] += ri0;
          rhs[3 * (size_t)cur + 1] += ri1;
          rhs[3 * (size_t)cur + 2] += ri2;
          diag[3 * (size_t)cur] += di0;
          diag[3 * (size_t)cur + 1] += di1;
          diag[3 * (size_t)cur + 2] += di2;
        }
        cur = i;
        ri0 = ri1 = ri2 = di0 = di1 = di2 = 0;
      }
      if (!((live >> q) & 1)) { /* no direction: no force, no stiffness */
        bs[0] = bs[1] = bs[2] = bs[3] = bs[4] = 0;
        continue;
      }
      bs[0] = uu[0][q];
      bs[1] = uu[1][q];
      bs[2] = uu[2][q];
      bs[3] = a4[q];
      bs[4] = b4[q];
      ri0 += e[0][q];
      ri1 += e[1][q];
      ri2 += e[2][q];
      di0 += qd[0][q];
      di1 += qd[1][q];
      di2 += qd[2][q];
      rhs[3 * (size_t)j] -= e[0][q];
      rhs[3 * (size_t)j + 1] -= e[1][q];
      rhs[3 * (size_t)j + 2] -= e[2][q];
      diag[3 * (size_t)j] += qd[0][q];
      diag[3 * (size_t)j + 1] += qd[1][q];
      diag[3 * (size_t)j + 2] += qd[2][q];
    }
  }
  *run = (msl_run_t){.cur = cur, .r = {ri0, ri1, ri2}, .d = {di0, di1, di2}};
  return s;
}
#endif

int ms_linear_simd_available(void) {
#ifdef MSL_HAVE_AVX2_PATH
  return __builtin_cpu_supports("avx2") ? 1 : 0;
#else
  return 0;
#endif
}

void ms_linear_rhs(ms_linear_t *L, const mass_spring_t *ms, double h, double *restrict rhs, double *restrict diag) {
  ms_linear_rhs_path(L, ms, h, rhs, diag, ms_linear_simd_available());
}

void ms_linear_rhs_path(ms_linear_t *L, const mass_spring_t *ms, double h, double *restrict rhs, double *restrict diag,
                        int simd) {
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
  msl_run_t run = {.cur = UINT32_MAX};
#ifdef MSL_HAVE_AVX2_PATH
  if (simd && ms_linear_simd_available()) s = msl_springs_avx2(L, ms, h, rhs, diag, &run);
#else
  (void)simd;
#endif
  while (s < ns) {
    const uint32_t i = sp[s].i;
    const double xi0 = x[3 * i], xi1 = x[3 * i + 1], xi2 = x[3 * i + 2];
    const double vi0 = v[3 * i], vi1 = v[3 * i + 1], vi2 = v[3 * i + 2];
    double ri0 = 0, ri1 = 0, ri2 = 0, di0 = 0, di1 = 0, di2 = 0;
    if (run.cur == i) { /* the vector loop's open run goes on */
      ri0 = run.r[0];
      ri1 = run.r[1];
      ri2 = run.r[2];
      di0 = run.d[0];
      di1 = run.d[1];
      di2 = run.d[2];
      run.cur = UINT32_MAX;
    } else
      msl_flush(&run, rhs, diag);
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
  msl_flush(&run, rhs, diag); /* the vector loop took every spring */
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
