/* SPDX-License-Identifier: Apache-2.0 */
#include "scene_limits.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define ROW(k, lo, lo_open, hi, hi_open, unit, why)                                                                    \
  { k, lo, hi, lo_open, hi_open, unit, why }

/* Organ-scale physics: a gram to tens of kilograms, micrometres to metres,
 * milliseconds. Each bound says why in the row (assets/scenes/README.md
 * "Ranges" repeats them). */
static const scene_limit_t table[] = {
    ROW("physics.dt", 1e-5, 0, 0.05, 0, "s",
        "below 10 us no step keeps real time (and 1e-300 divides to infinity); above 50 ms contact is no longer "
        "haptic"),
    ROW("physics.publish_hz", 1, 0, 240, 0, "Hz", "a viewer needs a frame a second; no display shows more than 240"),
    ROW("physics.quant_step", 1e-7, 0, 1e-2, 0, "m",
        "finer than 0.1 um is below float precision at organ size; coarser than 1 cm hides the deformation"),
    ROW("physics.gravity", -100, 0, 100, 0, "m/s^2", "10 g in any direction covers every lab orientation"),
    ROW("physics.sleep_speed", 0, 0, 0.1, 0, "m/s", "an organ moving faster than 10 cm/s is not at rest"),
    ROW("physics.sleep_after", 0, 1, 60, 0, "s", "a minute of stillness is evidence enough"),
    ROW("physics.publish_keepalive", 0, 0, 60, 0, "s", "a late joiner must see the organ within a minute"),
    ROW("organs.position", -10, 0, 10, 0, "m", "the surgical field lies within 10 m of the scene origin"),
    ROW("organs.scale", 1e-6, 0, 1e6, 0, "",
        "a unit conversion (um, mm, cm to m) with room; the scaled mesh is checked too"),
    ROW("organs.color", 0, 0, 1, 0, "", "RGB fractions"),
    ROW("organs.fixed_below", -10, 0, 10, 0, "m", "a height inside the surgical field"),
    ROW("organs.material.mass", 1e-3, 0, 20, 0, "kg",
        "a gram (the smallest tissue sample) to 20 kg (above any human organ); 1e-300 kg makes every contact step "
        "non-finite"),
    ROW("organs.material.stiffness", 0, 0, 1e7, 0, "N/m",
        "stiffer than 1e7 N/m is rigid at haptic rates and overflows the stable-step estimate"),
    ROW("organs.material.damping", 0, 0, 100, 0, "N s/m", "tissue damping is far below 100 N s/m"),
    ROW("organs.material.home_stiffness", 0, 0, 1e7, 0, "N/m", "as stiffness"),
    ROW("organs.material.home_damping", 0, 0, 100, 0, "N s/m", "as damping"),
    ROW("organs.material.bond_k", 0, 0, 1e7, 0, "N/m", "as stiffness"),
    ROW("organs.material.angle_k", 0, 0, 100, 0, "J", "100 J per bond angle is rigid at organ scale"),
    ROW("organs.material.stretch_bend_k", -1e4, 0, 1e4, 0, "N",
        "a coupling beyond 1e4 N cannot satisfy bond_k * angle_k > 2 k_sb^2 within their ranges"),
    ROW("organs.material.distance_stiffness", 0, 0, 1, 0, "", "a PBD stiffness is a fraction"),
    ROW("organs.material.volume_stiffness", 0, 0, 1, 0, "", "a PBD stiffness is a fraction"),
    ROW("organs.material.distance_compliance", 0, 0, 1, 0, "m/N", "softer than 1 m/N holds no shape"),
    ROW("organs.material.volume_compliance", 0, 0, 1, 0, "", "softer than 1 holds no volume"),
    ROW("organs.material.slope_m1", 0, 1, 10, 0, "", "a slope above 10 moves a node ten times the tool"),
    ROW("organs.material.slope_m2", 0, 1, 10, 0, "", "as slope_m1"),
    ROW("organs.material.slope_m3", 0, 1, 10, 0, "", "as slope_m1"),
    ROW("organs.material.refine_area", 0, 1, 1e-2, 0, "m^2", "a face of 10 cm x 10 cm is the whole organ"),
    ROW("organs.material.refine_levels", 1, 0, 4, 0, "", "each level quadruples the faces"),
    ROW("organs.solver.substeps", 0, 0, 256, 0, "", "more than 256 sub-steps per step cannot keep real time"),
    ROW("organs.solver.iterations", 1, 0, 1000, 0, "", "more than 1000 constraint iterations cannot keep real time"),
    ROW("organs.solver.cg_tolerance", 1e-12, 0, 0.1, 0, "", "below 1e-12 is round-off; above 0.1 is no solution"),
    ROW("organs.solver.cg_max_iterations", 1, 0, 10000, 0, "", "more cannot keep real time"),
    ROW("organs.solver.tet_size", 0, 0, 0.1, 0, "m", "0 = automatic; a 10 cm cell is coarser than any organ"),
    ROW("organs.solver.region_force", 0, 0, 0.01, 0, "N",
        "0 = regional sleeping off; 10 mN held by each sleeping node would be felt"),
    ROW("organs.solver.region_speed", 0, 0, 0.01, 0, "m/s", "1 cm/s is not at rest"),
    ROW("tools.radius", 0, 1, 0.05, 0, "m", "a laparoscopic tip is millimetres; 5 cm is a fist"),
    ROW("tools.length", 0, 1, 1, 0, "m", "a laparoscopic shaft is shorter than 1 m"),
    ROW("tools.stiffness", 0, 1, 1e5, 0, "N/m", "no haptic device renders a stiffer coupling"),
    ROW("tools.max_force", 0, 1, 100, 0, "N", "no haptic device renders more than 100 N"),
    ROW("tools.thresholds", 0, 1, 100, 0, "N", "a palpation level within what a device renders"),
    ROW("tools.friction", 0, 0, 2, 0, "", "a Coulomb coefficient on wet tissue is below 2"),
    ROW("tools.grasp_radius", 0, 1, 0.05, 0, "m", "as the tip radius"),
    ROW("tools.jaw_opening", 0, 1, 0.05, 0, "m", "as the tip radius"),
    ROW("tools.blade_length", 0, 1, 0.2, 0, "m", "a scalpel blade is centimetres"),
    ROW("objects.radius", 0, 1, 0.05, 0, "m", "a stone fits inside an organ"),
    ROW("objects.position", -10, 0, 10, 0, "m", "the surgical field lies within 10 m of the scene origin"),
    ROW("objects.color", 0, 0, 1, 0, "", "RGB fractions"),
    ROW("tasks.target", -10, 0, 10, 0, "m", "the surgical field lies within 10 m of the scene origin"),
    ROW("tasks.target_radius", 0, 1, 0.1, 0, "m", "a target wider than 10 cm is the whole organ"),
    ROW("tasks.distance", 0, 1, 0.5, 0, "m", "a pull longer than 50 cm tears any organ"),
};

const scene_limit_t *scene_limit(const char *key) {
  for (size_t i = 0; i < sizeof table / sizeof table[0]; i++)
    if (!strcmp(table[i].key, key)) return &table[i];
  return NULL;
}

const scene_limit_t *scene_limits_table(size_t *n) {
  *n = sizeof table / sizeof table[0];
  return table;
}

int scene_limit_ok(const scene_limit_t *l, double v) {
  if (!isfinite(v)) return 0;
  if (l->lo_open ? !(v > l->lo) : !(v >= l->lo)) return 0;
  if (l->hi_open ? !(v < l->hi) : !(v <= l->hi)) return 0;
  return 1;
}

void scene_limit_describe(const scene_limit_t *l, char *dst, size_t size) {
  snprintf(dst, size, "must be %s %g and %s %g%s%s", l->lo_open ? ">" : ">=", l->lo, l->hi_open ? "<" : "<=", l->hi,
           l->unit[0] ? " " : "", l->unit);
}

int scene_limit_check(const char *key, double v, char *dst, size_t size) {
  const scene_limit_t *l = scene_limit(key);
  if (!l) {
    snprintf(dst, size, "%s: no range known", key);
    return -1;
  }
  if (scene_limit_ok(l, v)) return 0;
  char want[96];
  scene_limit_describe(l, want, sizeof want);
  snprintf(dst, size, "%s = %g: %s (%s)", key, v, want, l->why);
  return -1;
}
