/* SPDX-License-Identifier: Apache-2.0 */
/* docs/numerics.md §5 case 2: stiffness ratio 1e6 inside one mesh.
 *
 * A bar of 13 x 3 x 3 nodes (1 cm spacing, 0.12 m long, 0.1 kg, 5 tets per
 * cell) hangs from its fixed x = 0 face under gravity along +x. Its edge
 * springs are soft (k = 100 N/m: the soft cells stretch by about 5 % under
 * the load) except a band of cells across the middle (rest x in
 * [0.04, 0.08] m for both nodes), whose springs are 1e6 times stiffer
 * (1e8 N/m). The load is switched on at rest and the bar swings down,
 * overshoots and settles (ground damping 20 /s per node): the transient
 * loads the band up to about twice its static load.
 *
 *  - implicit Euler (mass_spring_create_tets + k_scale, one linearised
 *    backward-Euler step per sub-step, CG to 1e-6) and XPBD (per-edge
 *    compliance factor 1e-6) at the 60 Hz scene step with 10 sub-steps for
 *    2 s: the largest strain of any stiff spring, over the whole run, must
 *    stay <= 1 % (XPBD: with 4 or more iterations per sub-step; 1 and 2
 *    leave 4.7 % and 2 %, printed; the strain must fall as iterations
 *    grow), and the soft part must carry the load (strain well above the
 *    band's: the stiff springs did not simply lock the whole mesh);
 *  - the explicit schemes report the step they would need: the stable dt
 *    from the power-iteration bound (mass_spring_eigen_bounds, through
 *    integrator_stable_dt) of the banded mesh must be below the soft mesh's
 *    by about sqrt(1e6) = 1000 (checked within 500 .. 2000), and that bound
 *    is real: symplectic Euler on the banded mesh stays bounded at 0.9x of it
 *    and diverges at 1.5x.
 * Every run must stay finite. */
#include "physics/integrator.h"
#include "physics/mass_spring.h"
#include "physics/pbd.h"
#include "stab_util.h"
#include "tet_mesh.h"

#define NX 13
#define H 0.01
#define MASS 0.1
#define K_SOFT 100.0
#define RATIO 1e6
#define DT (1.0 / 60)
#define SUB 10
#define T_END 2.0

static int in_band(const double *xi, const double *xj) {
  const double lo = 0.04 - 1e-9, hi = 0.08 + 1e-9;
  return xi[0] >= lo && xi[0] <= hi && xj[0] >= lo && xj[0] <= hi;
}

/* Largest |L/L0 - 1| over the springs in (band = 1) or out of (0) the band. */
static double strain_of(const double *x, const double *rest, const uint32_t *pair, size_t stride, size_t count,
                        const double *rest_len, int band) {
  double m = 0;
  for (size_t e = 0; e < count; e++) {
    uint32_t i = pair[stride * e], j = pair[stride * e + 1];
    if (in_band(rest + 3 * i, rest + 3 * j) != band || !(rest_len[e] > 0)) continue;
    m = fmax(m, fabs(v3_dist(x + 3 * i, x + 3 * j) / rest_len[e] - 1));
  }
  return m;
}

static double ms_strain(const mass_spring_t *ms, int band) {
  double worst = 0;
  for (size_t s = 0; s < ms->nsprings; s++) {
    const ms_spring_t *sp = &ms->springs[s];
    if (in_band(ms->x_rest + 3 * sp->i, ms->x_rest + 3 * sp->j) != band) continue;
    worst = fmax(worst, fabs(v3_dist(ms->x + 3 * sp->i, ms->x + 3 * sp->j) / sp->rest - 1));
  }
  return worst;
}

static int make_ms(mass_spring_t *ms, const tet_mesh_t *tm, int banded) {
  ms_params_t p = {.mass = MASS, .stiffness = K_SOFT, .damping = 0, .home_stiffness = 0, .gravity = {9.81, 0, 0}};
  verr_t err;
  if (mass_spring_create_tets(ms, tm, &p, &err)) {
    fprintf(stderr, "%s\n", err.msg);
    return -1;
  }
  ms->p.home_damping = 20 * ms->mass[0]; /* 20 /s relative to the ground */
  for (size_t i = 0; i < ms->n; i++)
    if (ms->x_rest[3 * i] < 1e-9) ms->inv_mass[i] = 0;
  if (!banded) return 0;
  double *scale = malloc(ms->nsprings * sizeof *scale);
  size_t nb = 0;
  for (size_t s = 0; s < ms->nsprings; s++) {
    int b = in_band(ms->x_rest + 3 * ms->springs[s].i, ms->x_rest + 3 * ms->springs[s].j);
    scale[s] = b ? RATIO : 1;
    nb += (size_t)b;
  }
  int rc = mass_spring_set_stiffness_scale(ms, scale, &err);
  free(scale);
  if (rc) fprintf(stderr, "%s\n", err.msg);
  CHECK(nb > 0 && nb < ms->nsprings);
  return rc;
}

static void test_implicit(const tet_mesh_t *tm) {
  mass_spring_t ms;
  integrator_t it;
  verr_t err;
  if (make_ms(&ms, tm, 1)) {
    CHECK(0);
    return;
  }
  CHECK(integrator_init(&it, INT_IMPLICIT_EULER, ms.n, 1e-6, 5000, &err) == 0);
  double stiff_max = 0, soft_end = 0;
  int finite = 1, cg_max = 0;
  for (int k = 0; k < (int)(T_END / DT + 0.5); k++) {
    for (int s = 0; s < SUB; s++) {
      integrator_substep(&it, &ms.fs, DT / SUB);
      cg_max = it.last_cg_iterations > cg_max ? it.last_cg_iterations : cg_max;
    }
    finite = finite && stab_finite(ms.x, 3 * ms.n) && stab_finite(ms.v, 3 * ms.n);
    stiff_max = fmax(stiff_max, ms_strain(&ms, 1));
  }
  soft_end = ms_strain(&ms, 0);
  printf("implicit Euler, %d sub-steps of %.3g ms: stiff-band strain max %.3e, soft strain at rest %.3f (CG up to %d "
         "iterations)\n",
         SUB, 1e3 * DT / SUB, stiff_max, soft_end, cg_max);
  CHECK(finite);
  CHECK(stiff_max <= 0.01);
  CHECK(soft_end > 0.02 && soft_end > 100 * stiff_max);
  integrator_destroy(&it);
  mass_spring_destroy(&ms);
}

static double test_xpbd(const tet_mesh_t *tm, int iterations) {
  pbd_params_t p = {.mode = PBD_MODE_XPBD,
                    .mass = MASS,
                    .distance_compliance = 1 / K_SOFT,
                    .volume_compliance = 1e3, /* alpha / h^2 so large the volume term does nothing: springs only */
                    .gravity = {9.81, 0, 0},
                    .substeps = SUB,
                    .iterations = iterations};
  pbd_t s;
  verr_t err;
  if (pbd_create(&s, tm->nnodes, tm->x, tm->ntets, tm->tets, &p, &err)) {
    fprintf(stderr, "%s\n", err.msg);
    CHECK(0);
    return NAN;
  }
  s.p.damping = 20 * s.mass[0];
  for (size_t i = 0; i < s.n; i++)
    if (s.x_rest[3 * i] < 1e-9) pbd_fix_node(&s, i);
  double *scale = malloc(s.nedges * sizeof *scale);
  for (size_t e = 0; e < s.nedges; e++)
    scale[e] = in_band(s.x_rest + 3 * s.edge[2 * e], s.x_rest + 3 * s.edge[2 * e + 1]) ? 1 / RATIO : 1;
  CHECK(pbd_set_edge_compliance_scale(&s, scale, &err) == 0);
  free(scale);
  double stiff_max = 0;
  int ok = 1;
  for (int k = 0; k < (int)(T_END / DT + 0.5); k++) {
    ok = ok && pbd_step(&s, DT, NULL, NULL) == 0 && stab_finite(s.x, 3 * s.n);
    stiff_max = fmax(stiff_max, strain_of(s.x, s.x_rest, s.edge, 2, s.nedges, s.edge_rest, 1));
  }
  double soft_end = strain_of(s.x, s.x_rest, s.edge, 2, s.nedges, s.edge_rest, 0);
  printf("XPBD, %d sub-steps x %d iteration(s): stiff-band strain max %.3e, soft strain at rest %.3f\n", SUB,
         iterations, stiff_max, soft_end);
  CHECK(ok && s.rollbacks == 0);
  /* Once the band holds, the soft cells carry the load (no global lock). */
  if (stiff_max <= 0.01) CHECK(soft_end > 0.02 && soft_end > 5 * stiff_max);
  pbd_destroy(&s);
  return ok ? stiff_max : NAN;
}

/* Symplectic Euler on the banded mesh from a small random displacement:
 * bounded (max offset below 1000x its start) for `steps` steps? */
static int symplectic_bounded(const tet_mesh_t *tm, double h, int steps) {
  mass_spring_t ms;
  integrator_t it;
  verr_t err;
  if (make_ms(&ms, tm, 1)) return -1;
  ms.p.gravity[0] = 0;
  ms.p.home_damping = 0;
  integrator_init(&it, INT_SYMPLECTIC_EULER, ms.n, 1e-6, 100, &err);
  stab_seed = 7;
  double start = 0;
  for (size_t c = 0; c < 3 * ms.n; c++) {
    if (ms.inv_mass[c / 3] > 0) ms.x[c] += 1e-7 * stab_rand();
    start = fmax(start, fabs(ms.x[c] - ms.x_rest[c]));
  }
  int bounded = 1;
  for (int k = 0; k < steps && bounded; k++) {
    integrator_substep(&it, &ms.fs, h);
    double off = 0;
    for (size_t c = 0; c < 3 * ms.n; c++) off = fmax(off, fabs(ms.x[c] - ms.x_rest[c]));
    bounded = isfinite(off) && off < 1e3 * start;
  }
  integrator_destroy(&it);
  mass_spring_destroy(&ms);
  return bounded;
}

static void test_explicit(const tet_mesh_t *tm) {
  mass_spring_t soft, band;
  if (make_ms(&soft, tm, 0) || make_ms(&band, tm, 1)) {
    CHECK(0);
    return;
  }
  /* Edge damping for explicit Euler's damped bound (lambda_c / lambda_k). */
  soft.p.damping = band.p.damping = 0.05;
  double lk_s, lc_s, lk_b, lc_b;
  CHECK(mass_spring_eigen_bounds(&soft, 0, &lk_s, &lc_s) == 0);
  CHECK(mass_spring_eigen_bounds(&band, 0, &lk_b, &lc_b) == 0);
  printf("omega_max: soft mesh %.4g rad/s, banded %.4g rad/s (ratio %.1f)\n", sqrt(lk_s), sqrt(lk_b),
         sqrt(lk_b / lk_s));
  printf("%-18s %14s %14s %10s  (stable dt from the power-iteration bound)\n", "scheme", "soft mesh s", "banded s",
         "ratio");
  const integrator_kind_t kinds[] = {INT_EXPLICIT_EULER, INT_SYMPLECTIC_EULER, INT_VERLET, INT_RK4};
  for (int i = 0; i < 4; i++) {
    double ds = integrator_stable_dt(kinds[i], lk_s, lc_s), db = integrator_stable_dt(kinds[i], lk_b, lc_b);
    double r = ds / db;
    printf("%-18s %14.4g %14.4g %10.1f  -> %.0f sub-steps per 60 Hz step\n", integrator_name(kinds[i]), ds, db, r,
           ceil(DT / db));
    CHECK(db > 0 && isfinite(db));
    /* sqrt(1e6) for the oscillatory bounds; explicit Euler's damped bound
     * c / omega^2 goes as 1/k, so 1e6 for it. */
    if (kinds[i] == INT_EXPLICIT_EULER)
      CHECK(r >= 5e5 && r <= 2e6);
    else
      CHECK(r >= 500 && r <= 2000);
  }
  double hb = integrator_stable_dt(INT_SYMPLECTIC_EULER, lk_b, 0);
  int below = symplectic_bounded(tm, 0.9 * hb, 5000), above = symplectic_bounded(tm, 1.5 * hb, 5000);
  printf("symplectic Euler on the banded mesh: bounded at 0.9x the bound: %s, at 1.5x: %s\n", below ? "yes" : "no",
         above ? "yes" : "no");
  CHECK(below == 1);
  CHECK(above == 0);
  mass_spring_destroy(&soft);
  mass_spring_destroy(&band);
}

int main(void) {
  tet_mesh_t tm;
  verr_t err;
  if (tet_mesh_box_grid(NX, 3, 3, H, &tm, &err)) {
    fprintf(stderr, "%s\n", err.msg);
    return 1;
  }
  printf("bar %d x 3 x 3 nodes (%zu tets), soft k %g N/m, band x in [0.04, 0.08] m %g times stiffer, 60 Hz step\n", NX,
         tm.ntets, K_SOFT, RATIO);
  test_implicit(&tm);
  /* XPBD: Gauss-Seidel needs a few iterations per sub-step to carry the
   * load through the near-rigid band; one or two leave it stretched by
   * several percent (reported, not the setting the case asks about). The
   * strain must fall as iterations grow and be <= 1 % from 4 on. */
  double prev = INFINITY;
  for (int it = 1; it <= 8; it *= 2) {
    double e = test_xpbd(&tm, it);
    CHECK(e < prev);
    if (it >= 4) CHECK(e <= 0.01);
    prev = e;
  }
  test_explicit(&tm);
  tet_mesh_free(&tm);
  return check_report("stab_stiff_band");
}
