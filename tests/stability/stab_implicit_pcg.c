/* SPDX-License-Identifier: Apache-2.0 */
/* The large-step integrator implicit_pcg (issue 17.3, physics/integrator.h)
 * on stiff and extreme cases, through the real runtime (proxy, patch,
 * implicit tool coupling), the kidney mesh (2,000 vertices).
 *
 * Each case presses the probe from 2 mm above the highest rest vertex to
 * 5 mm below it over 0.1 s, holds it 1 s, then pulls it 30 mm up in one
 * step (a release) and runs 0.5 s more. Required: one step per scene step
 * whatever the tool stiffness, no roll-back, every state finite; at the end
 * of the hold the surface at rest (every vertex slower than 1e-6 m/s, from
 * step-to-step displacement) and the force steady to 1 % over 0.1 s; after
 * the release the surface slower than it was at the release's first step
 * (nothing gains energy from the jump).
 *
 *   default      the kidney's live material, 400 N/m probe, 1 ms
 *   default      also: the steady force within 2 % of symplectic Euler's
 *                at 20 sub-steps (the felt stiffness is the tissue's, not
 *                the scheme's)
 *   stiff_tool   40,000 N/m probe (100x): the same step count; stable, but
 *                not required at rest: under symplectic Euler (2 sub-steps)
 *                the surface keeps moving at 1e-4 m/s too (the proxy's
 *                re-projection against so stiff a spring, not the scheme)
 *   stiff_tissue edge and home springs 100x, mass 10x lighter: omega_max
 *                about 30x beyond symplectic Euler's bound at 1 ms
 *   large_step   dt 33 ms (a 30 Hz scene step) with the 400 N/m probe:
 *                stable (the 0.1 s press is 3 steps, the proxy ends deeper;
 *                rest within 1 s is not required)
 *   pinned       the lower half of the kidney fixed (fixed_below)
 *   few_iter     solver.cg_max_iterations 1 under the stiff tissue */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "press_hold.h"
#include "runtime/scene_runtime.h"
#include "scene.h"
#include "test_runtime.h"
#include "vmath.h"

static const char *KIDNEY = "    model: mass_spring_surface\n"
                            "    integrator: %s\n"
                            "    material: {mass: %g, stiffness: %g, damping: 0.02, home_stiffness: %g, "
                            "home_damping: 0.005}\n%s";

static press_result_t run_case(const char *name, const char *integ, double mass, double k, const char *extra,
                               const char *probe, double dt) {
  static scene_t sc;
  static runtime_t rt;
  press_result_t r = {0};
  char organ[768];
  snprintf(organ, sizeof organ, KIDNEY, integ, mass, k, k, extra);
  verr_t err;
  if (!test_runtime_one_organ(NULL, &sc, name, "kidney.obj", organ, probe, &err)) {
    CHECK(!"kidney scene loads");
    return r;
  }
  sc.dt = dt;
  if (runtime_init(&rt, &sc, &err)) {
    fprintf(stderr, "%s: %s\n", name, err.msg);
    CHECK(!"runtime starts");
    return r;
  }
  r = press(&rt);
  printf("%-13s %-16s sub %d  finite %d  rollbacks %llu  contact %d  speed %.2e m/s  force %.5f N  spread %.2e  "
         "release speed %.2e -> %.2e m/s\n",
         name, integ, r.substeps, r.finite, (unsigned long long)r.rollbacks, r.contact, r.speed, r.force, r.spread,
         r.release_speed0, r.release_speed_end);
  runtime_destroy(&rt);
  return r;
}

/* settle 0: stable only (finite, no roll-back, contact kept, the release
 * dies out), not required at rest (see the file comment). */
static void check_case(const press_result_t *r, int settle) {
  CHECK(settle ? r->ok : r->finite && r->contact && r->rollbacks == 0 && r->force > 0);
  CHECK(r->substeps == 1);
  CHECK(r->release_speed_end < r->release_speed0 || r->release_speed0 == 0);
}

/* physics.integrator selects the scheme of every organ that names none,
 * with implicit_pcg's own CG budget; an organ's key wins. */
static void scene_selects(void) {
  static scene_t sc;
  verr_t err;
  const char *yaml = "scene: s\nphysics: {dt: 0.001, integrator: implicit_pcg}\norgans:\n"
                     "  - {name: a, mesh: a.obj}\n  - {name: b, mesh: b.obj, integrator: verlet}\n"
                     "  - {name: c, mesh: c.obj, solver: {cg_max_iterations: 3}}\n";
  CHECK(scene_load_string(yaml, "s.yaml", NULL, &sc, &err) == 0);
  CHECK(!strcmp(sc.organs[0].integrator, "implicit_pcg"));
  CHECK(sc.organs[0].solver.cg_max_iterations == SCENE_PCG_ITERATIONS);
  CHECK(!strcmp(sc.organs[1].integrator, "verlet"));
  CHECK(!strcmp(sc.organs[2].integrator, "implicit_pcg") && sc.organs[2].solver.cg_max_iterations == 3);
  CHECK(scene_load_string("scene: s\nphysics: {integrator: backward}\norgans:\n  - {name: a, mesh: a.obj}\n", "s.yaml",
                          NULL, &sc, &err) != 0);
  printf("scene: physics.integrator refused a wrong name: %s\n", err.msg);
}

int main(void) {
  scene_selects();
  const char *p400 = "radius: 0.003, stiffness: 400, max_force: 4";
  const char *p40k = "radius: 0.003, stiffness: 40000, max_force: 40";
  press_result_t def = run_case("default", "implicit_pcg", 0.15, 30, "", p400, 0.001);
  check_case(&def, 1);
  press_result_t stiff_tool = run_case("stiff_tool", "implicit_pcg", 0.15, 30, "", p40k, 0.001);
  check_case(&stiff_tool, 0);

  /* The felt stiffness: the steady force for the same dent is the tissue's
   * (the explicit-coupled symplectic reference, 20 sub-steps). */
  press_result_t ref = run_case("reference", "symplectic_euler", 0.15, 30, "    solver: {substeps: 20}\n", p400, 0.001);
  CHECK(ref.ok);
  CHECK(fabs(def.force - ref.force) <= 0.02 * ref.force);
  press_result_t stiff = run_case("stiff_tissue", "implicit_pcg", 0.015, 3000, "", p400, 0.001);
  check_case(&stiff, 1);
  press_result_t large = run_case("large_step", "implicit_pcg", 0.15, 30, "", p400, 0.033);
  check_case(&large, 0);
  press_result_t pinned = run_case("pinned", "implicit_pcg", 0.15, 30, "    fixed_below: 0.0\n", p400, 0.001);
  check_case(&pinned, 1);
  press_result_t few =
      run_case("few_iter", "implicit_pcg", 0.015, 3000, "    solver: {cg_max_iterations: 1}\n", p40k, 0.001);
  check_case(&few, 1);
  return check_report("stab_implicit_pcg");
}
