/* SPDX-License-Identifier: Apache-2.0 */
/* docs/numerics.md §5 case 11: 360 and 720 degree twist, release.
 *
 * A bar 0.24 x 0.03 x 0.03 m (a closed box surface, filled with tetrahedra
 * by the scene models themselves at solver.tet_size 1 cm), 0.2 kg, is
 * twisted about its long axis by 360 or 720 degrees (the angle grows
 * linearly along the bar, so no tetrahedron is inverted at the start) and
 * released at rest, free (no home springs, no gravity: the two ends
 * untwist against each other; no fixed node, so nothing does work on it).
 * Every tetrahedral scene model, built through model_create as a scene
 * would build it, at the 60 Hz scene step:
 *
 *   - mass_spring_tet + implicit_euler (edge springs 200 N/m, Kelvin-Voigt
 *     damping 0.05 N s/m, ground damping 0.003 N s/m per node, about 5 /s;
 *     one guarded implicit sub-step per scene step, CG to 1e-8);
 *   - xpbd (distance compliance 1/200 m/N, volume compliance 1e-10, same
 *     ground damping; 10 sub-steps x 5 iterations). At volume compliance
 *     1e-9 the volume term is too weak to stop 114 tets inverting at 720
 *     degrees; at 1e-11 five iterations no longer converge the stiff
 *     volume constraints and the stored energy C^2 / 2 alpha jumps by up to
 *     1 % of E0 between steps: 1e-10 is the setting where both hold;
 *   - pbd (stiffness 1, same ground damping, sub-steps and iterations).
 *
 * Pass: the state stays finite, no rollback; for XPBD and PBD every
 * tetrahedron keeps a positive volume at every step of the 2 s (checked
 * every step, the start included); for the models that define an energy
 * (mass-spring, XPBD; PBD has none, its constraints are rigid) the total
 * energy sampled every scene step never rises by more than the tolerance
 * below and ends below 10 % of E0.
 *
 * mass_spring_tet has edge springs only, nothing that resists inversion: at
 * 720 degrees 152 of 1,080 tets invert on the way back (and with 10
 * sub-steps, less numerical damping, 35 already at 360 degrees); it can
 * come to rest partly inverted (3.8 % of E0 left at 2 s). That is the
 * model, not the integrator (the energy still decays monotonically): the
 * count is printed and checked to be the known failure (> 0 at 720
 * degrees), as case 8 asks of edge-only springs; scenes that twist tissue
 * this far need a model with a volume term (XPBD/PBD).
 *
 * "Monotonically", the tolerance: every force here dissipates (ground and
 * Kelvin-Voigt damping remove energy at every instant; nothing is fixed, so
 * nothing does work), so the exact trajectory's energy never rises and any
 * rise is a scheme error.
 *   - XPBD: 1e-9 x E0. Its sub-step is a projection with implicit ground
 *     damping and dissipates; what remains is rounding of a sum of ~3,000
 *     terms (1e-13 of E0). Measured: no rise at all.
 *   - implicit Euler: 1e-3 x E(t) per scene step. One linearised step does
 *     not conserve or dissipate energy exactly on a nonlinear system (raw, unguarded
 *     steps of 1/60 s raised it by 9e-4 E0 at 360 degrees on a similar bar
 *     with one end fixed, and diverged at 720); the model therefore guards each sub-step, accepting it only if
 *     the energy rose by no more than 1e-3 of the kinetic + elastic energy
 *     (model_mass_spring.c) and halving it otherwise. The test holds the
 *     model to that contract, which is what the live server does.
 * The molecular model has no volume notion (bonds and angles on the surface,
 * no tetrahedra), so "no inverted tets" does not apply to it: not run here. */
#include "stab_util.h"
#include "tet_mesh.h"

#define DT (1.0 / 60)
#define T_END 2.0
#define TET_SIZE 0.01
#define LX 0.24
#define LYZ 0.03

static void twist(const double *rest, size_t n, double turns, double *x) {
  double c = 0.5 * LYZ;
  for (size_t i = 0; i < n; i++) {
    const double *r = rest + 3 * i;
    double a = 2 * M_PI * turns * r[0] / LX, y = r[1] - c, z = r[2] - c;
    x[3 * i] = r[0];
    x[3 * i + 1] = c + cos(a) * y - sin(a) * z;
    x[3 * i + 2] = c + sin(a) * y + cos(a) * z;
  }
}

static double *rest_volume; /* ntets, filled in main */

static size_t inverted(const tet_mesh_t *tm, const double *x, double *min_ratio) {
  size_t bad = 0;
  double mr = INFINITY;
  for (size_t t = 0; t < tm->ntets; t++) {
    double v = tet_volume(tm, x, t), v0 = rest_volume[t];
    bad += v <= 0;
    mr = fmin(mr, v / v0);
  }
  if (min_ratio) *min_ratio = fmin(*min_ratio, mr);
  return bad;
}

typedef struct run {
  size_t inverted_max; /* most inverted tets at any step */
  double min_ratio;    /* smallest V/V0 seen */
  double rise_max;     /* largest E(k+1) - E(k) - tol(k), J, over the allowed rise (<= 0: within it) */
  double rise_rel;     /* largest E(k+1) - E(k) over E0 */
  double e0, e_end;
  int finite;
  uint64_t rollbacks;
} run_t;

/* tol_e0: allowed rise as a fraction of E0; tol_e: as a fraction of E(k). */
static run_t run_model(const char *yaml, const mesh_t *box, const tet_mesh_t *tm, double turns, double tol_e0,
                       double tol_e) {
  run_t r = {0, INFINITY, -INFINITY, 0, NAN, NAN, 1, 0};
  scene_organ_t cfg = stab_organ(yaml);
  verr_t err;
  model_t *m = stab_model(&cfg, box, NULL, DT, &err);
  if (!m) {
    fprintf(stderr, "%s\n", err.msg);
    r.finite = 0;
    return r;
  }
  /* The model meshed the same surface with the same size: same nodes. */
  CHECK(m->nnodes == tm->nnodes && m->ntets == tm->ntets);
  if (m->nnodes != tm->nnodes) {
    model_destroy(m);
    r.finite = 0;
    return r;
  }
  twist(tm->x, tm->nnodes, turns, m->x);
  memset(m->v, 0, 3 * m->nnodes * sizeof(double));
  model_note_outside_write(m);
  r.inverted_max = inverted(tm, m->x, &r.min_ratio);
  double e = r.e0 = m->ops->energy(m);
  for (int k = 0; k < (int)(T_END / DT + 0.5); k++) {
    r.finite =
        r.finite && m->ops->step(m, DT) == 0 && stab_finite(m->x, 3 * m->nnodes) && stab_finite(m->v, 3 * m->nnodes);
    size_t bad = inverted(tm, m->x, &r.min_ratio);
    if (bad > r.inverted_max) r.inverted_max = bad;
    double en = m->ops->energy(m);
    if (isfinite(en)) {
      r.rise_max = fmax(r.rise_max, en - e - (tol_e0 * r.e0 + tol_e * e));
      r.rise_rel = fmax(r.rise_rel, (en - e) / r.e0);
    }
    e = en;
  }
  r.e_end = e;
  r.rollbacks = m->rollbacks;
  model_destroy(m);
  return r;
}

static void check_run(const char *what, double turns, const run_t *r, int has_energy, int has_volume) {
  printf("%-30s %4.0f deg: inverted max %zu, min V/V0 %.3f, E0 %.4g J, E_end/E0 %.2e, largest rise %.2e x E0\n", what,
         360 * turns, r->inverted_max, r->min_ratio, r->e0, r->e_end / r->e0, r->rise_rel);
  CHECK(r->finite && r->rollbacks == 0);
  if (has_volume) CHECK(r->inverted_max == 0);
  if (has_energy) {
    CHECK(r->e0 > 0);
    CHECK(r->rise_max <= 0);
    CHECK(r->e_end <= 0.1 * r->e0);
  }
}

static const char *MATERIAL =
    "    material: {mass: 0.2, stiffness: 200, damping: 0.05, home_stiffness: 0, home_damping: "
    "0.003, distance_stiffness: 1, volume_stiffness: 1, distance_compliance: 0.005, "
    "volume_compliance: 1.0e-10}\n";

int main(void) {
  mesh_t box;
  stab_box(&box, 24, 3, 3, LX, LYZ, LYZ);
  tet_mesh_t tm;
  tet_embedding_t emb;
  tet_build_report_t rep;
  verr_t err;
  if (tet_mesh_build(&box, TET_SIZE, &tm, &emb, &rep, &err)) {
    fprintf(stderr, "%s\n", err.msg);
    return 1;
  }
  rest_volume = malloc(tm.ntets * sizeof *rest_volume);
  for (size_t t = 0; t < tm.ntets; t++) rest_volume[t] = tet_volume(&tm, tm.x, t);
  printf("bar %.2f x %.2f x %.2f m: %zu nodes, %zu tets, free, twisted and released at rest, dt 1/60 s, %.0f s\n", LX,
         LYZ, LYZ, tm.nnodes, tm.ntets, T_END);
  char ms[512], xp[512], pb[512];
  snprintf(ms, sizeof ms,
           "    model: mass_spring_tet\n    integrator: implicit_euler\n    solver: {tet_size: %g, cg_tolerance: "
           "1.0e-8, cg_max_iterations: 5000}\n%s",
           TET_SIZE, MATERIAL);
  snprintf(xp, sizeof xp, "    model: xpbd\n    solver: {tet_size: %g, substeps: 10, iterations: 5}\n%s", TET_SIZE,
           MATERIAL);
  snprintf(pb, sizeof pb, "    model: pbd\n    solver: {tet_size: %g, substeps: 10, iterations: 5}\n%s", TET_SIZE,
           MATERIAL);
  for (int tw = 1; tw <= 2; tw++) {
    run_t r = run_model(ms, &box, &tm, tw, 0, 1e-3);
    check_run("mass_spring_tet implicit_euler", tw, &r, 1, 0);
    if (tw == 2) {
      printf("  (edge springs only: %zu tets inverted at worst; expected, no volume term)\n", r.inverted_max);
      CHECK(r.inverted_max > 0);
    }
    r = run_model(xp, &box, &tm, tw, 1e-9, 0);
    check_run("xpbd 10 sub x 5 it", tw, &r, 1, 1);
    r = run_model(pb, &box, &tm, tw, 0, 0);
    check_run("pbd 10 sub x 5 it (no energy)", tw, &r, 0, 1);
  }
  printf("molecular: not run (no tetrahedra, no volume notion: bonds and angles on the surface)\n");
  free(rest_volume);
  tet_mesh_free(&tm);
  tet_embedding_free(&emb);
  mesh_free(&box);
  return check_report("stab_twist");
}
