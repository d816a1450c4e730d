/* SPDX-License-Identifier: Apache-2.0 */
/* Tool coupling for xpbd and pbd (issue 17.1; pbd.h): the probe's spring
 * acts as its penalty force in the prediction and its stiffness is taken
 * implicitly after the solver's iterations (coupling.h's rank-one solve on
 * the sub-step's velocity), so a stiff probe does not feed back through a
 * whole sub-step explicitly.
 *
 * Per model (kidney mesh, 0.15 kg, scene defaults but 8 mm tetrahedra: a
 * fifth of the automatic fill's 7,120, so the test takes seconds), press-and-hold of
 * press_hold.h: with a 400 N/m probe 5 mm down, the steady force equals, to
 * 1e-6 relative, that of the same model with the spring explicit
 * (declarations ignored: the penalty force alone) at the same probe
 * position; with 4,000 N/m, 0.5 mm down (no clamp reached), the press is
 * stable and settles, to the penalty form's force (1e-6); with 40,000 N/m,
 * 0.2 mm down, it is stable (finite, no roll-back, contact, surface speed
 * below 1e-4 m/s) where the penalty form buzzes (printed beside it:
 * docs/numerics.md). */
#include <math.h>
#include <stdio.h>

#include "check.h"
#include "press_hold.h"
#include "test_runtime.h"

static runtime_t rt;
static scene_t sc;

/* depth: m below the highest rest vertex; the force limits (tool 100 N, device 4 N) stay above the held force so the
 * stiff spring is not softened by a clamp. */
static press_result_t run(const char *name, const char *keys, double k, double depth, int implicit) {
  char probe[96];
  press_result_t r = {0};
  snprintf(probe, sizeof probe, "radius: 0.003, stiffness: %g, max_force: 100", k);
  if (!test_runtime_one_organ(&rt, &sc, "coupling-pbd", "kidney.obj", keys, probe, NULL)) {
    CHECK(!"kidney scene loads");
    return r;
  }
  CHECK(rt.organs[0].model->implicit_tools);
  if (!implicit) rt.organs[0].model->implicit_tools = 0; /* declarations ignored: the penalty force alone */
  r = press_to(&rt, depth, 4);
  printf("%s %5.0f N/m %s: finite %d, rollbacks %llu, contact %d, force %.5f N, speed %.2e m/s, spread %.2e\n", name, k,
         implicit ? "implicit" : "penalty ", r.finite, (unsigned long long)r.rollbacks, r.contact, r.force, r.speed,
         r.spread);
  runtime_destroy(&rt);
  return r;
}

int main(void) {
  const char *names[2] = {"xpbd", "pbd"};
  const char *models[2] = {"    model: xpbd\n    material: {mass: 0.15}\n    solver: {tet_size: 0.008}\n",
                           "    model: pbd\n    material: {mass: 0.15}\n    solver: {tet_size: 0.008}\n"};
  for (int mi = 0; mi < 2; mi++) {
    const double ks[2] = {400, 4000}, depth[2] = {0.005, 0.0005};
    for (int k = 0; k < 2; k++) {
      press_result_t c = run(names[mi], models[mi], ks[k], depth[k], 1);
      press_result_t e = run(names[mi], models[mi], ks[k], depth[k], 0);
      CHECK(c.ok && c.force < 4);
      CHECK(e.finite && e.rollbacks == 0 && e.contact && e.force > 0);
      printf("  force at the same dent: implicit %.6f N, penalty %.6f N (%+.2e relative)\n", c.force, e.force,
             (c.force - e.force) / e.force);
      CHECK(fabs(c.force - e.force) <= 1e-6 * e.force);
    }
    press_result_t s = run(names[mi], models[mi], 40000, 0.0002, 1);
    CHECK(s.finite && s.rollbacks == 0 && s.contact && s.force > 0 && s.speed < 1e-4);
    run(names[mi], models[mi], 40000, 0.0002, 0); /* for the record: the penalty form */
  }
  return check_report("stab_coupling_pbd");
}
