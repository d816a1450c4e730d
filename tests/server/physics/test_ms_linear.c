/* SPDX-License-Identifier: Apache-2.0 */
/* ms_linear_rhs's two spring loops (server/physics/ms_linear.c, the fused
 * pass of implicit_pcg): the AVX2 loop (four springs at a time, taken when
 * the processor has AVX2) against the scalar loop, bit for bit in rhs, the
 * Jacobi diagonal and the cached blocks, on the kidney asset's
 * mass_spring_surface springs with random perturbed positions and
 * velocities, external forces; then with per-spring stiffness factors,
 * residual forces, fixed nodes and one zero-length spring; then with the
 * springs shuffled and every third one's ends swapped (runs of equal i
 * broken up); each also with 1-3 springs left out, so the scalar loop
 * finishes a run the vector loop left open. A wrong lane, order or run
 * hand-over changes bits (and the relative difference, also printed, must
 * stay below 1e-12). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "physics/ms_linear.h"
#include "test_assets.h"
#include "ms_kidney.h"
#include "ms_shuffle.h"
#include "test_rng.h"

static void compare(const char *label, mass_spring_t *ms, ms_linear_t *L) {
  const size_t m = 3 * ms->n, full = ms->nsprings;
  double *r0 = malloc(m * sizeof *r0), *d0 = malloc(m * sizeof *d0), *r1 = malloc(m * sizeof *r1);
  double *d1 = malloc(m * sizeof *d1), *b0 = malloc(5 * full * sizeof *b0);
  CHECK(r0 && d0 && r1 && d1 && b0);
  if (!(r0 && d0 && r1 && d1 && b0)) goto done;
  for (size_t cut = 0; cut < 4; cut++) {
    ms->nsprings = full - cut;
    const double h = 1e-3;
    ms_linear_rhs_path(L, ms, h, r0, d0, 0);
    memcpy(b0, L->blk, 5 * ms->nsprings * sizeof *b0);
    ms_linear_rhs_path(L, ms, h, r1, d1, 1);
    double e = fmax(ms_rel_diff(r1, r0, m), ms_rel_diff(d1, d0, m));
    printf("%-36s springs %zu: simd (%s) against scalar rel diff %.3g\n", label, ms->nsprings,
           ms_linear_simd_available() ? "AVX2" : "not available here: scalar twice", e);
    CHECK(e < 1e-12);
    CHECK(memcmp(r1, r0, m * sizeof *r0) == 0);
    CHECK(memcmp(d1, d0, m * sizeof *d0) == 0);
    CHECK(memcmp(L->blk, b0, 5 * ms->nsprings * sizeof *b0) == 0);
  }
done:
  ms->nsprings = full;
  free(r0);
  free(d0);
  free(r1);
  free(d1);
  free(b0);
}

int main(void) {
  mesh_t mesh;
  if (test_mesh_load("kidney.obj", &mesh)) return 1;
  verr_t err;
  mass_spring_t ms;
  CHECK(ms_kidney_create(&ms, &mesh, &err) == 0);
  ms_linear_t L = {0};
  CHECK(ms_linear_reserve(&L, ms.nsprings, &err) == 0);
  const size_t n = ms.n, m = 3 * n, ns = ms.nsprings;
  double *scale = malloc(ns * sizeof *scale);
  CHECK(scale != NULL && ns > 1000);
  if (!scale) return check_report("test_ms_linear");
  uint64_t rng = 20261127;
  double len = 0;
  for (size_t s = 0; s < ns; s++) len = fmax(len, ms.springs[s].rest);
  /* Perturbations of the order of a spring: stretched and compressed
   * springs, so the geometric clamp acts on some. */
  for (size_t c = 0; c < m; c++) {
    ms.x[c] = ms.x_rest[c] + 0.4 * len * (test_rng_uniform(&rng) - 0.5);
    ms.v[c] = 0.2 * (test_rng_uniform(&rng) - 0.5);
    ms.f_ext[c] = 0.01 * (test_rng_uniform(&rng) - 0.5);
  }
  compare("sorted, uniform stiffness", &ms, &L);
  for (size_t s = 0; s < ns; s++) scale[s] = 0.25 + 2 * test_rng_uniform(&rng);
  CHECK(mass_spring_set_stiffness_scale(&ms, scale, &err) == 0);
  CHECK(mass_spring_reserve(&ms, n, 1, &err) == 0 && ms.f_res);
  for (size_t c = 0; c < m; c++) ms.f_res[c] = 0.02 * (test_rng_uniform(&rng) - 0.5);
  CHECK(mass_spring_fix_below(&ms, ms.x_rest[2]) <= n);
  uint32_t zi = ms.springs[11].i, zj = ms.springs[11].j; /* a zero-length spring */
  memcpy(ms.x + 3 * (size_t)zj, ms.x + 3 * (size_t)zi, 3 * sizeof(double));
  compare("k_scale + f_res + fixed + zero length", &ms, &L);
  ms_shuffle_springs(&ms, &rng);
  mass_spring_springs_changed(&ms);
  compare("shuffled + k_scale + f_res + zero", &ms, &L);
  free(scale);
  ms_linear_free(&L);
  mass_spring_destroy(&ms);
  mesh_free(&mesh);
  return check_report("test_ms_linear");
}
