/* SPDX-License-Identifier: Apache-2.0 */
/* Tool coupling out of adaptive_mass_spring's stability bounds (issue
 * 17.1): the tool spring is taken implicitly (physics/coupling.h, in the
 * coarse sub-step and in the refined region's sub-cycle), so neither the
 * coarse sub-steps (power iteration) nor the refined region's ratio
 * (node_bound) depend on the tool, and the stiffness the hand feels does
 * not change.
 *
 * Kidney mesh, the material of assets/scenes/kidney_adaptive.yaml (refines
 * under the probe, two levels). With a 400 N/m and a 4,000 N/m probe: the
 * sub-steps at rest and the most sub-steps of any step of the
 * press-and-hold of press_hold.h (refined then) are equal; the press with
 * the 4,000 N/m probe is stable (finite, no roll-back, contact). The held
 * force with the 400 N/m probe equals, to 1 %, that of the same model with
 * the coupling explicit (declarations ignored, 20 coarse sub-steps), at
 * the same probe position. */
#include <math.h>
#include <stdio.h>

#include "check.h"
#include "press_hold.h"
#include "test_runtime.h"

#define ADAPTIVE_KEYS                                                                                                  \
  "    model: adaptive_mass_spring\n    integrator: symplectic_euler\n"                                                \
  "    material: {mass: 0.15, stiffness: 30, damping: 0.02, home_stiffness: 30, home_damping: 0.005, "                 \
  "refine_area: 1.0e-6, refine_levels: 2}\n"

static runtime_t rt;
static scene_t sc;

static int load(const char *organ, double k) {
  char probe[96];
  snprintf(probe, sizeof probe, "radius: 0.003, stiffness: %g, max_force: 4", k);
  return test_runtime_one_organ(&rt, &sc, "coupling-adaptive", "kidney.obj", organ, probe, NULL);
}

int main(void) {
  const double ks[2] = {400, 4000};
  press_result_t r[2];
  for (int k = 0; k < 2; k++) {
    if (!load(ADAPTIVE_KEYS, ks[k])) {
      CHECK(!"kidney scene loads");
      return check_report("stab_coupling_adaptive");
    }
    CHECK(rt.organs[0].model->implicit_tools);
    r[k] = press(&rt);
    printf("probe %5.0f N/m: sub-steps at rest %d, most while pressed %d; finite %d, rollbacks %llu, contact %d, "
           "force %.5f N, speed %.2e m/s, spread %.2e\n",
           ks[k], r[k].substeps, r[k].max_substeps, r[k].finite, (unsigned long long)r[k].rollbacks, r[k].contact,
           r[k].force, r[k].speed, r[k].spread);
    runtime_destroy(&rt);
  }
  CHECK(r[0].substeps == r[1].substeps && r[0].substeps >= 1);
  /* Refined while pressed (more sub-steps than at rest), by the same ratio. */
  CHECK(r[0].max_substeps > r[0].substeps);
  CHECK(r[0].max_substeps == r[1].max_substeps);
  CHECK(r[1].finite && r[1].rollbacks == 0 && r[1].contact && r[1].force > 0);
  CHECK(r[0].finite && r[0].rollbacks == 0 && r[0].contact && r[0].force > 0);

  /* The felt stiffness: the explicit coupling at 20 coarse sub-steps. */
  if (load(ADAPTIVE_KEYS "    solver: {substeps: 20}\n", 400)) {
    rt.organs[0].model->implicit_tools = 0; /* declarations ignored: explicit */
    press_result_t e = press(&rt);
    printf("explicit 400 N/m, 20 sub-steps: force %.5f N (implicit %.5f N, %+.3f %%), rollbacks %llu\n", e.force,
           r[0].force, 100 * (r[0].force - e.force) / e.force, (unsigned long long)e.rollbacks);
    CHECK(e.finite && e.rollbacks == 0 && e.contact && e.force > 0);
    CHECK(fabs(r[0].force - e.force) <= 0.01 * e.force);
    runtime_destroy(&rt);
  } else {
    CHECK(!"kidney scene loads");
  }
  return check_report("stab_coupling_adaptive");
}
