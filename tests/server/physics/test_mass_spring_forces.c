/* SPDX-License-Identifier: Apache-2.0 */
/* The run-based spring loops of mass_spring_forces and
 * mass_spring_stiffness_mul (server/physics/mass_spring.c) against a
 * straightforward reference written here (one spring at a time, the
 * formula of mass_spring.h), on the kidney asset (assets/meshes/kidney.obj,
 * mass_spring_surface springs) with random perturbed positions and
 * velocities, per-spring stiffness factors, residual forces f_res, external
 * forces, fixed nodes, one zero-length spring, and the spring array
 * shuffled (with some springs' ends swapped) so the runs of equal i are
 * broken. The maximum difference relative to the largest reference
 * component must stay below 1e-12 (only the summation order differs); a
 * wrong damping term, scatter sign or geometric term would be off by O(1).
 * The zero-length spring must leave every force finite. The AVX2 spring
 * loops (gather and scatter, taken when the processor has AVX2) and the
 * scalar one must agree bit for bit in every case; after the in-place
 * shuffle the gather index is rebuilt (mass_spring_springs_changed). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "physics/mass_spring.h"
#include "test_assets.h"
#include "ms_kidney.h"
#include "ms_shuffle.h"
#include "test_rng.h"

/* Reference: every spring on its own, both ends written per spring. */
static void ref_forces(const mass_spring_t *ms, const double *x, const double *v, double *f) {
  const ms_params_t *p = &ms->p;
  for (size_t c = 0; c < 3 * ms->n; c++) {
    size_t i = c / 3;
    int k = (int)(c % 3);
    f[c] = ms->f_ext[c] + ms->mass[i] * p->gravity[k] - p->home_stiffness * (x[c] - ms->x_rest[c]) -
           p->home_damping * v[c] + (ms->f_res ? ms->f_res[c] : 0);
  }
  for (size_t s = 0; s < ms->nsprings; s++) {
    uint32_t i = ms->springs[s].i, j = ms->springs[s].j;
    double d[3], dv[3], len = 0, dvu = 0;
    for (int k = 0; k < 3; k++) {
      d[k] = x[3 * j + k] - x[3 * i + k];
      dv[k] = v[3 * j + k] - v[3 * i + k];
      len += d[k] * d[k];
    }
    len = sqrt(len);
    if (len <= 1e-300) continue;
    for (int k = 0; k < 3; k++) {
      d[k] /= len;
      dvu += dv[k] * d[k];
    }
    double ks = p->stiffness * (ms->k_scale ? ms->k_scale[s] : 1);
    double mag = ks * (len - ms->springs[s].rest) + p->damping * dvu;
    for (int k = 0; k < 3; k++) {
      f[3 * i + k] += mag * d[k];
      f[3 * j + k] -= mag * d[k];
    }
  }
}

static void ref_stiffness_mul(const mass_spring_t *ms, const double *x, double a, double b, const double *y,
                              double *out) {
  const ms_params_t *p = &ms->p;
  for (size_t c = 0; c < 3 * ms->n; c++) out[c] = (a * p->home_stiffness + b * p->home_damping) * y[c];
  for (size_t s = 0; s < ms->nsprings; s++) {
    uint32_t i = ms->springs[s].i, j = ms->springs[s].j;
    double u[3], w[3], len = 0, wu = 0;
    for (int k = 0; k < 3; k++) {
      u[k] = x[3 * j + k] - x[3 * i + k];
      len += u[k] * u[k];
    }
    len = sqrt(len);
    if (len <= 1e-300) continue;
    double ks = p->stiffness * (ms->k_scale ? ms->k_scale[s] : 1);
    double geo = 1 - ms->springs[s].rest / len;
    if (ms->definite_jacobian && geo < 0) geo = 0;
    geo *= a * ks;
    for (int k = 0; k < 3; k++) {
      u[k] /= len;
      w[k] = y[3 * i + k] - y[3 * j + k];
      wu += w[k] * u[k];
    }
    for (int k = 0; k < 3; k++) {
      double t = (a * ks + b * p->damping) * wu * u[k] + geo * (w[k] - wu * u[k]);
      out[3 * i + k] += t;
      out[3 * j + k] -= t;
    }
  }
}

static void compare(const char *label, const mass_spring_t *ms, const double *x, const double *v, const double *y,
                    double *got, double *want) {
  size_t m = 3 * ms->n;
  mass_spring_forces(ms, x, v, got);
  ref_forces(ms, x, v, want);
  double e = ms_rel_diff(got, want, m);
  printf("%-34s forces rel diff %.3g\n", label, e);
  CHECK(e < 1e-12);
  /* The two spring loops (mass_spring.h): scalar and AVX2 give the same
   * forces, here to 1e-12 and, as the header promises, bit for bit. */
  double *alt = malloc(m * sizeof *alt);
  CHECK(alt != NULL);
  if (alt) {
    mass_spring_forces_path(ms, x, v, alt, 0);
    mass_spring_forces_path(ms, x, v, got, 1);
    e = ms_rel_diff(got, alt, m);
    CHECK(e < 1e-12);
    CHECK(memcmp(got, alt, m * sizeof *alt) == 0);
    printf("%-34s simd (%s) against scalar rel diff %.3g\n", label,
           mass_spring_simd_available() ? "AVX2 gather" : "not available here: scalar twice", e);
    CHECK(!mass_spring_simd_available() || ms->gather.g); /* the gather loop ran, not its fallback */
    mass_spring_forces_path(ms, x, v, got, 2);            /* the AVX2 scatter loop */
    CHECK(memcmp(got, alt, m * sizeof *alt) == 0);
    free(alt);
  }
  static const double ab[3][2] = {{1, 0}, {0, 1}, {1, 0.37}};
  for (int q = 0; q < 3; q++) {
    mass_spring_stiffness_mul(ms, x, ab[q][0], ab[q][1], y, got);
    ref_stiffness_mul(ms, x, ab[q][0], ab[q][1], y, want);
    e = ms_rel_diff(got, want, m);
    printf("%-34s stiffness_mul(a %g, b %g) rel diff %.3g\n", label, ab[q][0], ab[q][1], e);
    CHECK(e < 1e-12);
  }
}

int main(void) {
  mesh_t mesh;
  if (test_mesh_load("kidney.obj", &mesh)) return 1;
  verr_t err;
  mass_spring_t ms;
  CHECK(ms_kidney_create(&ms, &mesh, &err) == 0);
  CHECK(ms.nsprings > 1000);
  size_t n = ms.n, m = 3 * n, ns = ms.nsprings;
  double *x = malloc(m * sizeof *x), *v = malloc(m * sizeof *v), *y = malloc(m * sizeof *y);
  double *got = malloc(m * sizeof *got), *want = malloc(m * sizeof *want), *scale = malloc(ns * sizeof *scale);
  CHECK(x && v && y && got && want && scale);
  uint64_t rng = 20261121;
  double h = 0;
  for (size_t s = 0; s < ns; s++) h = fmax(h, ms.springs[s].rest);
  for (int trial = 0; trial < 4; trial++) {
    /* Perturbations of the order of the spring length: stretched and
     * compressed springs, so the geometric term changes sign. */
    for (size_t c = 0; c < m; c++) {
      x[c] = ms.x_rest[c] + 0.4 * h * (test_rng_uniform(&rng) - 0.5);
      v[c] = 0.2 * (test_rng_uniform(&rng) - 0.5);
      y[c] = test_rng_uniform(&rng) - 0.5;
      ms.f_ext[c] = trial == 3 ? 0.01 * (test_rng_uniform(&rng) - 0.5) : 0;
    }
    compare("sorted, uniform stiffness", &ms, x, v, y, got, want);
    ms.definite_jacobian = 1;
    compare("sorted, definite jacobian", &ms, x, v, y, got, want);
    ms.definite_jacobian = 0;
  }

  /* Per-spring factors, residual forces, fixed nodes. */
  for (size_t s = 0; s < ns; s++) scale[s] = 0.25 + 2 * test_rng_uniform(&rng);
  scale[7] = 0;
  CHECK(mass_spring_set_stiffness_scale(&ms, scale, &err) == 0);
  CHECK(mass_spring_reserve(&ms, n, 1, &err) == 0 && ms.f_res);
  for (size_t c = 0; c < m; c++) ms.f_res[c] = 0.02 * (test_rng_uniform(&rng) - 0.5);
  CHECK(mass_spring_fix_below(&ms, ms.x_rest[2]) <= n);
  compare("k_scale + f_res", &ms, x, v, y, got, want);

  /* A zero-length spring: move spring 11's j onto its i. */
  uint32_t zi = ms.springs[11].i, zj = ms.springs[11].j;
  for (int k = 0; k < 3; k++) x[3 * zj + k] = x[3 * zi + k];
  compare("k_scale + f_res + zero length", &ms, x, v, y, got, want);

  /* Shuffled springs (Fisher-Yates, factors moved with them) and every third
   * spring's ends swapped: runs of equal i broken up. */
  ms_shuffle_springs(&ms, &rng);
  mass_spring_springs_changed(&ms); /* the AVX2 loop's gather index follows the new order */
  size_t runs = 0;
  for (size_t s = 0; s < ns; s++) runs += s == 0 || ms.springs[s].i != ms.springs[s - 1].i;
  printf("shuffled: %zu runs of equal i for %zu springs\n", runs, ns);
  CHECK(runs > ns / 2);
  compare("shuffled + k_scale + f_res + zero", &ms, x, v, y, got, want);
  CHECK(mass_spring_set_stiffness_scale(&ms, NULL, &err) == 0);
  compare("shuffled, uniform stiffness", &ms, x, v, y, got, want);

  free(x);
  free(v);
  free(y);
  free(got);
  free(want);
  free(scale);
  mass_spring_destroy(&ms);
  mesh_free(&mesh);
  return check_report("test_ms_forces");
}
