/* SPDX-License-Identifier: Apache-2.0 */
/* bench_ms_forces: ns per spring of mass_spring_forces and
 * mass_spring_stiffness_mul (the run-based loops of mass_spring.c) against
 * the loop they replaced (kept here only, as the reference: one spring at a
 * time through v3_normalize, both ends scattered), on the kidney surface
 * (assets/meshes/kidney.obj, 2,000 nodes, 5,994 springs, the classroom
 * scene's organ) with springs as built (sorted by i) and shuffled. Prints a
 * table; the best of several repeats is reported (the machine may be
 * shared). The "forces avx2" rows compare the scalar spring loop (old
 * column) with the AVX2 one (new column) of mass_spring_forces_path, the
 * "avx2 gather" rows the AVX2 scatter loop (old) with the AVX2 gather loop
 * (new, the default). Without --quick also on the gallbladder (5,393
 * nodes, 16,173 springs).
 * usage: bench_ms_forces [--quick] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "physics/mass_spring.h"
#include "test_assets.h"
#include "test_rng.h"
#include "vmath.h"

/* The loop before the rewrite (spring part only; the node part is shared). */
static void old_forces(const mass_spring_t *ms, const double *x, const double *v, double *f) {
  const ms_params_t *p = &ms->p;
  for (size_t i = 0; i < ms->n; i++) {
    const double *xi = x + 3 * i, *vi = v + 3 * i, *xr = ms->x_rest + 3 * i;
    double *fi = f + 3 * i;
    for (int k = 0; k < 3; k++)
      fi[k] = ms->f_ext[3 * i + k] + ms->mass[i] * p->gravity[k] - p->home_stiffness * (xi[k] - xr[k]) -
              p->home_damping * vi[k];
  }
  if (ms->f_res)
    for (size_t c = 0; c < 3 * ms->n; c++) f[c] += ms->f_res[c];
  for (size_t s = 0; s < ms->nsprings; s++) {
    const ms_spring_t *sp = &ms->springs[s];
    double d[3], dv[3];
    v3_sub(d, x + 3 * sp->j, x + 3 * sp->i);
    double len = v3_normalize(d);
    if (len <= 1e-300) continue;
    v3_sub(dv, v + 3 * sp->j, v + 3 * sp->i);
    double k = ms->k_scale ? p->stiffness * ms->k_scale[s] : p->stiffness;
    double mag = k * (len - sp->rest) + p->damping * v3_dot(dv, d);
    v3_axpy(f + 3 * sp->i, d, mag);
    v3_axpy(f + 3 * sp->j, d, -mag);
  }
}

static void old_stiffness_mul(const mass_spring_t *ms, const double *x, double a, double b, const double *y,
                              double *out) {
  const ms_params_t *p = &ms->p;
  double diag = a * p->home_stiffness + b * p->home_damping;
  for (size_t c = 0; c < 3 * ms->n; c++) out[c] = diag * y[c];
  for (size_t s = 0; s < ms->nsprings; s++) {
    const ms_spring_t *sp = &ms->springs[s];
    double ks = ms->k_scale ? p->stiffness * ms->k_scale[s] : p->stiffness;
    double axial = a * ks + b * p->damping;
    double u[3], w[3], t[3];
    v3_sub(u, x + 3 * sp->j, x + 3 * sp->i);
    double len = v3_normalize(u);
    if (len <= 1e-300) continue;
    double geo = 1 - sp->rest / len;
    if (ms->definite_jacobian && geo < 0) geo = 0;
    geo *= a * ks;
    v3_sub(w, y + 3 * sp->i, y + 3 * sp->j);
    double wu = v3_dot(w, u);
    for (int k = 0; k < 3; k++) t[k] = axial * wu * u[k] + geo * (w[k] - wu * u[k]);
    v3_add(out + 3 * sp->i, out + 3 * sp->i, t);
    v3_sub(out + 3 * sp->j, out + 3 * sp->j, t);
  }
}

static double now_ns(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return 1e9 * (double)t.tv_sec + (double)t.tv_nsec;
}

typedef void (*forces_fn)(const mass_spring_t *, const double *, const double *, double *);
typedef void (*kmul_fn)(const mass_spring_t *, const double *, double, double, const double *, double *);

static double sink;

/* The two spring loops of mass_spring.c, for the scalar / AVX2 rows. */
static void forces_scalar(const mass_spring_t *ms, const double *x, const double *v, double *f) {
  mass_spring_forces_path(ms, x, v, f, 0);
}
static void forces_simd(const mass_spring_t *ms, const double *x, const double *v, double *f) {
  mass_spring_forces_path(ms, x, v, f, 1);
}
static void forces_scatter(const mass_spring_t *ms, const double *x, const double *v, double *f) {
  mass_spring_forces_path(ms, x, v, f, 2);
}

/* Best over `repeats` of the mean ns per spring of `calls` calls. */
static double time_forces(forces_fn fn, const mass_spring_t *ms, const double *x, const double *v, double *f,
                          int repeats, int calls) {
  double best = INFINITY;
  for (int r = 0; r < repeats; r++) {
    double t0 = now_ns();
    for (int c = 0; c < calls; c++) fn(ms, x, v, f);
    best = fmin(best, (now_ns() - t0) / calls / (double)ms->nsprings);
    sink += f[0];
  }
  return best;
}

static double time_kmul(kmul_fn fn, const mass_spring_t *ms, const double *x, const double *y, double *out, int repeats,
                        int calls) {
  double best = INFINITY;
  for (int r = 0; r < repeats; r++) {
    double t0 = now_ns();
    for (int c = 0; c < calls; c++) fn(ms, x, 1, 0.01, y, out);
    best = fmin(best, (now_ns() - t0) / calls / (double)ms->nsprings);
    sink += out[0];
  }
  return best;
}

static int organ(const char *name, int repeats, int calls) {
  mesh_t mesh;
  if (test_mesh_load(name, &mesh)) return 1;
  verr_t err;
  mass_spring_t ms;
  ms_params_t p = {.mass = 0.15, .stiffness = 400, .damping = 0.8, .home_stiffness = 5, .gravity = {0, 0, -9.81}};
  if (mass_spring_create_surface(&ms, &mesh, &p, &err)) {
    fprintf(stderr, "bench_ms_forces: %s\n", err.msg);
    return 1;
  }
  size_t m = 3 * ms.n;
  double *x = malloc(m * sizeof *x), *v = malloc(m * sizeof *v), *y = malloc(m * sizeof *y), *f = malloc(m * sizeof *f);
  if (!x || !v || !y || !f) return 1;
  uint64_t rng = 7;
  for (size_t c = 0; c < m; c++) {
    x[c] = ms.x_rest[c] + 1e-4 * (test_rng_uniform(&rng) - 0.5);
    v[c] = 0.01 * (test_rng_uniform(&rng) - 0.5);
    y[c] = test_rng_uniform(&rng) - 0.5;
  }
  printf("%s: %zu nodes, %zu springs; best of %d x %d calls, ns per spring\n", name, ms.n, ms.nsprings, repeats, calls);
  printf("%-10s %-14s %8s %8s %8s\n", "springs", "function", "old", "new", "new/old");
  for (int order = 0; order < 2; order++) {
    if (order == 1) /* Fisher-Yates: runs of equal i of length ~1 */
      for (size_t s = ms.nsprings - 1; s > 0; s--) {
        size_t r = (size_t)(test_rng_uniform(&rng) * (double)(s + 1));
        ms_spring_t t = ms.springs[s];
        ms.springs[s] = ms.springs[r];
        ms.springs[r] = t;
      }
    if (order == 1) mass_spring_springs_changed(&ms);
    const char *label = order ? "shuffled" : "as built";
    double fo = time_forces(old_forces, &ms, x, v, f, repeats, calls);
    double fn = time_forces(mass_spring_forces, &ms, x, v, f, repeats, calls);
    printf("%-10s %-14s %8.2f %8.2f %8.2f\n", label, "forces", fo, fn, fn / fo);
    /* Scalar loop (old column) against the AVX2 loop (new column). */
    double fs = time_forces(forces_scalar, &ms, x, v, f, repeats, calls);
    double fv = time_forces(forces_simd, &ms, x, v, f, repeats, calls);
    printf("%-10s %-14s %8.2f %8.2f %8.2f%s\n", label, "forces avx2", fs, fv, fv / fs,
           mass_spring_simd_available() ? "" : " (no AVX2 here: scalar twice)");
    /* The AVX2 scatter loop (old column) against the gather one (new). */
    double fsc = time_forces(forces_scatter, &ms, x, v, f, repeats, calls);
    printf("%-10s %-14s %8.2f %8.2f %8.2f\n", label, "avx2 gather", fsc, fv, fv / fsc);
    double ko = time_kmul(old_stiffness_mul, &ms, x, y, f, repeats, calls);
    double kn = time_kmul(mass_spring_stiffness_mul, &ms, x, y, f, repeats, calls);
    printf("%-10s %-14s %8.2f %8.2f %8.2f\n", label, "stiffness_mul", ko, kn, kn / ko);
  }
  if (!isfinite(sink)) printf("(non-finite result)\n");
  free(x);
  free(v);
  free(y);
  free(f);
  mass_spring_destroy(&ms);
  mesh_free(&mesh);
  return 0;
}

int main(int argc, char **argv) {
  int quick = argc > 1 && strcmp(argv[1], "--quick") == 0;
  int repeats = quick ? 2 : 15, calls = quick ? 20 : 400;
  int rc = organ("kidney.obj", repeats, calls);
  if (!quick) rc |= organ("gallbladder.obj", repeats, calls / 3);
  return rc;
}
