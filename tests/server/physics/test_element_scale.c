/* SPDX-License-Identifier: Apache-2.0 */
/* Per-element stiffness (mass_spring_set_stiffness_scale,
 * pbd_set_edge_compliance_scale) and edge-only PBD meshes
 * (pbd_create_edges):
 *
 *  - bad factors (negative, NaN, Inf) and out-of-range edges are refused
 *    with a message naming the element; NULL clears a factor array;
 *  - mass-spring with factors: forces are -grad of the potential (central
 *    differences), stiffness_mul matches finite differences of the forces,
 *    a factor of 2 everywhere gives exactly the forces of twice the
 *    stiffness, and the eigenvalue bound grows with the stiffest spring;
 *  - XPBD with a factor 0 (rigid) on one link of a hanging three-node chain
 *    keeps that link at its rest length while the compliant one stretches
 *    by m g alpha; a chain from pbd_create_edges has no tetrahedra. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "physics/mass_spring.h"
#include "physics/pbd.h"
#include "tet_mesh.h"

static void test_mass_spring_scale(void) {
  tet_mesh_t tm;
  verr_t err;
  CHECK(tet_mesh_box_grid(3, 2, 2, 0.01, &tm, &err) == 0);
  ms_params_t p = {.mass = 0.01, .stiffness = 50, .damping = 0, .home_stiffness = 1, .gravity = {0, 0, -9.81}};
  mass_spring_t a, b;
  CHECK(mass_spring_create_tets(&a, &tm, &p, &err) == 0);
  ms_params_t p2 = p;
  p2.stiffness = 100;
  CHECK(mass_spring_create_tets(&b, &tm, &p2, &err) == 0);
  size_t ns = a.nsprings;
  double scale[256];
  CHECK(ns < 256);

  /* Refusals. */
  for (size_t s = 0; s < ns; s++) scale[s] = 1;
  scale[3] = -1;
  CHECK(mass_spring_set_stiffness_scale(&a, scale, &err) == -1 && strstr(err.msg, "spring 3"));
  scale[3] = NAN;
  CHECK(mass_spring_set_stiffness_scale(&a, scale, &err) == -1 && a.k_scale == NULL);
  scale[3] = INFINITY;
  CHECK(mass_spring_set_stiffness_scale(&a, scale, &err) == -1);

  /* Factor 2 everywhere == stiffness 2x, exactly. */
  for (size_t s = 0; s < ns; s++) scale[s] = 2;
  CHECK(mass_spring_set_stiffness_scale(&a, scale, &err) == 0 && a.k_scale != NULL);
  double x[3 * 64], v[3 * 64], fa[3 * 64], fb[3 * 64];
  CHECK(a.n <= 64);
  unsigned seed = 5;
  for (size_t c = 0; c < 3 * a.n; c++) {
    seed = seed * 1664525u + 1013904223u;
    x[c] = a.x_rest[c] + 2e-3 * ((double)(seed >> 8) / 16777216.0 - 0.5);
    v[c] = 0;
  }
  mass_spring_forces(&a, x, v, fa);
  mass_spring_forces(&b, x, v, fb);
  double worst = 0;
  for (size_t c = 0; c < 3 * a.n; c++) worst = fmax(worst, fabs(fa[c] - fb[c]));
  CHECK(worst == 0);
  CHECK(mass_spring_potential(&a, x) == mass_spring_potential(&b, x));

  /* Non-uniform factors: F = -grad U and K = -dF/dx by central differences. */
  for (size_t s = 0; s < ns; s++) scale[s] = s % 3 == 0 ? 1e3 : 0.5;
  CHECK(mass_spring_set_stiffness_scale(&a, scale, &err) == 0);
  mass_spring_forces(&a, x, v, fa);
  double rel = 0, fmaxv = 0, h = 1e-7;
  for (size_t c = 0; c < 3 * a.n; c++) fmaxv = fmax(fmaxv, fabs(fa[c]));
  for (size_t c = 0; c < 3 * a.n; c++) {
    double xc = x[c];
    x[c] = xc + h;
    double up = mass_spring_potential(&a, x);
    x[c] = xc - h;
    double um = mass_spring_potential(&a, x);
    x[c] = xc;
    rel = fmax(rel, fabs(-(up - um) / (2 * h) - fa[c]) / fmaxv);
  }
  printf("mass-spring with factors 0.5 / 1e3: |F + grad U| <= %.2e of max |F|\n", rel);
  CHECK(rel < 1e-6);
  double y[3 * 64], ky[3 * 64], xp[3 * 64], fp[3 * 64], fm[3 * 64];
  for (size_t c = 0; c < 3 * a.n; c++) y[c] = (c % 5) * 0.1 - 0.2;
  mass_spring_stiffness_mul(&a, x, 1, 0, y, ky);
  for (size_t c = 0; c < 3 * a.n; c++) xp[c] = x[c] + h * y[c];
  mass_spring_forces(&a, xp, v, fp);
  for (size_t c = 0; c < 3 * a.n; c++) xp[c] = x[c] - h * y[c];
  mass_spring_forces(&a, xp, v, fm);
  double krel = 0, kmax = 0;
  for (size_t c = 0; c < 3 * a.n; c++) kmax = fmax(kmax, fabs(ky[c]));
  for (size_t c = 0; c < 3 * a.n; c++) krel = fmax(krel, fabs(-(fp[c] - fm[c]) / (2 * h) - ky[c]) / kmax);
  printf("mass-spring with factors: |K y + dF/dx y| <= %.2e of max |K y|\n", krel);
  CHECK(krel < 1e-5);

  /* The stability bound sees the stiff springs. */
  double lk_a, lc_a, lk_b, lc_b;
  CHECK(mass_spring_eigen_bounds(&a, 0, &lk_a, &lc_a) == 0);
  CHECK(mass_spring_eigen_bounds(&b, 0, &lk_b, &lc_b) == 0);
  CHECK(lk_a > 100 * lk_b);

  /* NULL clears. */
  CHECK(mass_spring_set_stiffness_scale(&a, NULL, &err) == 0 && a.k_scale == NULL);
  mass_spring_destroy(&a);
  mass_spring_destroy(&b);
  tet_mesh_free(&tm);
}

static void test_pbd_edges(void) {
  const double x[9] = {0, 0, 0, 0, 0, -0.1, 0, 0, -0.2};
  const uint32_t bad[4] = {0, 1, 1, 3};
  const uint32_t edges[6] = {0, 1, 2, 1, 1, 2}; /* the repeat (1, 2) = (2, 1) is one constraint */
  pbd_params_t p = {.mode = PBD_MODE_XPBD,
                    .mass = 0.3,
                    .distance_compliance = 1e-3,
                    .gravity = {0, 0, -9.81},
                    .substeps = 20,
                    .iterations = 20};
  pbd_t s;
  verr_t err;
  CHECK(pbd_create_edges(&s, 3, x, 2, bad, &p, &err) == -1 && strstr(err.msg, "node 3"));
  CHECK(pbd_create_edges(&s, 3, x, 0, edges, &p, &err) == -1);
  CHECK(pbd_create(&s, 3, x, 0, NULL, &p, &err) == -1);
  CHECK(pbd_create_edges(&s, 3, x, 3, edges, &p, &err) == 0);
  CHECK(s.nedges == 2 && s.ntets == 0);
  pbd_fix_node(&s, 0);
  double sc[2] = {1, NAN};
  CHECK(pbd_set_edge_compliance_scale(&s, sc, &err) == -1 && s.edge_alpha_scale == NULL);
  sc[1] = -2;
  CHECK(pbd_set_edge_compliance_scale(&s, sc, &err) == -1);
  /* Link (0, 1) rigid, link (1, 2) compliant. */
  for (size_t e = 0; e < s.nedges; e++) sc[e] = s.edge[2 * e] == 0 ? 0 : 1;
  CHECK(pbd_set_edge_compliance_scale(&s, sc, &err) == 0);
  s.p.damping = 0.1 * 5; /* settle */
  int ok = 1;
  for (int k = 0; k < 600; k++) ok &= pbd_step(&s, 1.0 / 60, NULL, NULL) == 0;
  CHECK(ok);
  double l01 = fabs(s.x[5] - s.x[2]), l12 = fabs(s.x[8] - s.x[5]);
  /* Node 2 (0.1 kg) hangs from the compliant link: stretch m g alpha. */
  double want = 0.1 * 9.81 * 1e-3;
  printf("XPBD chain from edges: rigid link %.3e m off its rest length, compliant link stretched %.4e m (m g alpha "
         "%.4e m)\n",
         l01 - 0.1, l12 - 0.1, want);
  CHECK(fabs(l01 - 0.1) < 1e-6);
  CHECK(fabs((l12 - 0.1) - want) < 0.02 * want);
  /* The rigid link stores no energy; the compliant one C^2 / 2 alpha. */
  CHECK(isfinite(pbd_energy(&s)));
  CHECK(pbd_set_edge_compliance_scale(&s, NULL, &err) == 0 && s.edge_alpha_scale == NULL);
  pbd_destroy(&s);
}

int main(void) {
  test_mass_spring_scale();
  test_pbd_edges();
  return check_report("test_element_scale");
}
