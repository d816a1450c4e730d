/* SPDX-License-Identifier: Apache-2.0 */
/* test_scene: the scene parser gives the file's values and the documented
 * defaults, and every class of mistake is refused with a message that names
 * the right line and field. Most cases go through scene_load_string; a temp
 * directory covers what only scene_load does (open, read, directory). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "test_assets.h"
#include "scene.h"
#include "scene_expect.h"

static scene_t s; /* large: keep it off the stack */
static verr_t e;

/* See scene_expect.h. */
static int fails_with(const char *yaml, const char *a, const char *b) { return scene_fails_with(&s, &e, yaml, a, b); }
static int loads(const char *yaml, const char *base_dir) { return scene_loads(&s, &e, yaml, base_dir); }

/* Lines 1-4 of most cases: one valid organ, so line 5 is the first free one. */
#define HEAD "scene: demo\norgans:\n  - name: kidney\n    mesh: k.obj\n"

static const char full[] = "# full scene\n"                       /* 1 */
                           "scene: full-test\n"                   /* 2 */
                           "description: \"Every field given\"\n" /* 3 */
                           "physics:\n"                           /* 4 */
                           "  dt: 0.0005\n"                       /* 5 */
                           "  publish_hz: 60\n"                   /* 6 */
                           "  quant_step: 2e-6\n"                 /* 7 */
                           "  gravity: [0, 0, -9.81]\n"           /* 8 */
                           "organs:\n"                            /* 9 */
                           "  - name: kidney\n"                   /* 10 */
                           "    mesh: ../meshes/kidney.obj\n"     /* 11 */
                           "    model: mass_spring_surface\n"     /* 12 */
                           "    integrator: explicit_euler\n"     /* 13 */
                           "    position: [0.01, -0.02, 0.03]\n"  /* 14 */
                           "    scale: 0.5\n"                     /* 15 */
                           "    color: [0.9, 0.2, 0.1]\n"         /* 16 */
                           "    fixed_below: -0.01\n"             /* 17 */
                           "    material:\n"                      /* 18 */
                           "      mass: 0.15\n"                   /* 19 */
                           "      stiffness: 400\n"               /* 20 */
                           "      damping: 0.8\n"                 /* 21 */
                           "      home_stiffness: 80\n"           /* 22 */
                           "      home_damping: 0.1\n"            /* 23 */
                           "  - name: liver_2\n"                  /* 24 */
                           "    mesh: /abs/liver.obj\n"           /* 25 */
                           "tools:\n"                             /* 26 */
                           "  - name: probe1\n"                   /* 27 */
                           "    kind: probe\n"                    /* 28 */
                           "    radius: 0.003\n"                  /* 29 */
                           "    length: 0.12\n"                   /* 30 */
                           "    stiffness: 400\n"                 /* 31 */
                           "    max_force: 5\n"                   /* 32 */
                           "  - {name: probe2}\n";                /* 33 */

static void test_full_scene(void) {
  CHECK(loads(full, "/data/scenes"));
  CHECK(!strcmp(s.path, "t.yaml"));
  CHECK(!strcmp(s.name, "full-test"));
  CHECK(!strcmp(s.description, "Every field given"));
  CHECK_NEAR(s.dt, 0.0005, 1e-15);
  CHECK_NEAR(s.publish_hz, 60, 0);
  CHECK_NEAR(s.quant_step, 2e-6, 1e-18);
  CHECK_NEAR(s.gravity[0], 0, 0);
  CHECK_NEAR(s.gravity[2], -9.81, 1e-12);
  CHECK(s.norgans == 2);
  const scene_organ_t *o = &s.organs[0];
  CHECK(!strcmp(o->name, "kidney"));
  CHECK(!strcmp(o->mesh, "/data/scenes/../meshes/kidney.obj"));
  CHECK(!strcmp(o->model, "mass_spring_surface"));
  CHECK(!strcmp(o->integrator, "explicit_euler"));
  CHECK_NEAR(o->position[0], 0.01, 1e-15);
  CHECK_NEAR(o->position[1], -0.02, 1e-15);
  CHECK_NEAR(o->position[2], 0.03, 1e-15);
  CHECK_NEAR(o->scale, 0.5, 0);
  CHECK_NEAR(o->color[0], 0.9, 1e-6);
  CHECK_NEAR(o->color[1], 0.2, 1e-6);
  CHECK_NEAR(o->color[2], 0.1, 1e-6);
  CHECK(o->fixed_below_set == 1);
  CHECK_NEAR(o->fixed_below, -0.01, 1e-15);
  CHECK_NEAR(o->material.mass, 0.15, 1e-15);
  CHECK_NEAR(o->material.stiffness, 400, 0);
  CHECK_NEAR(o->material.damping, 0.8, 1e-15);
  CHECK_NEAR(o->material.home_stiffness, 80, 0);
  CHECK_NEAR(o->material.home_damping, 0.1, 1e-15);
  CHECK(o->line == 10);
  /* The second organ gave only name and mesh: everything else is default. */
  o = &s.organs[1];
  CHECK(!strcmp(o->name, "liver_2"));
  CHECK(!strcmp(o->mesh, "/abs/liver.obj")); /* absolute: not joined */
  CHECK(!strcmp(o->integrator, "symplectic_euler"));
  CHECK(o->line == 24);
  CHECK(o->fixed_below_set == 0);
  CHECK_NEAR(o->material.stiffness, 30, 0);
  CHECK(s.ntools == 2);
  const scene_tool_t *t = &s.tools[0];
  CHECK(!strcmp(t->name, "probe1"));
  CHECK(!strcmp(t->kind, "probe"));
  CHECK_NEAR(t->radius, 0.003, 1e-15);
  CHECK_NEAR(t->length, 0.12, 1e-15);
  CHECK_NEAR(t->stiffness, 400, 0);
  CHECK_NEAR(t->max_force, 5, 0);
  CHECK(t->line == 27);
  CHECK(s.tools[1].line == 33);
  CHECK(!strcmp(s.tools[1].name, "probe2"));
}

static void test_defaults(void) {
  CHECK(loads(HEAD, NULL));
  CHECK(!strcmp(s.description, ""));
  CHECK_NEAR(s.dt, 0.001, 0);
  CHECK_NEAR(s.publish_hz, 30, 0);
  CHECK_NEAR(s.quant_step, 1e-5, 0);
  for (int k = 0; k < 3; k++) CHECK_NEAR(s.gravity[k], 0, 0);
  CHECK(s.norgans == 1 && s.ntools == 0);
  const scene_organ_t *o = &s.organs[0];
  CHECK(!strcmp(o->mesh, "k.obj")); /* base_dir NULL: relative to the cwd */
  CHECK(!strcmp(o->model, "mass_spring_surface"));
  CHECK(!strcmp(o->integrator, "symplectic_euler"));
  for (int k = 0; k < 3; k++) CHECK_NEAR(o->position[k], 0, 0);
  CHECK_NEAR(o->scale, 1, 0);
  CHECK_NEAR(o->color[0], 0.8, 1e-6);
  CHECK_NEAR(o->color[1], 0.35, 1e-6);
  CHECK_NEAR(o->color[2], 0.3, 1e-6);
  CHECK(o->fixed_below_set == 0);
  CHECK_NEAR(o->material.mass, 0.1, 0);
  CHECK_NEAR(o->material.stiffness, 30, 0);
  CHECK_NEAR(o->material.damping, 0.02, 0);
  CHECK_NEAR(o->material.home_stiffness, 30, 0);
  CHECK_NEAR(o->material.home_damping, 0.005, 0);
  CHECK(o->line == 3);

  CHECK(loads(HEAD "tools:\n  - name: p\n", NULL));
  CHECK(s.ntools == 1);
  CHECK(!strcmp(s.tools[0].kind, "probe"));
  CHECK_NEAR(s.tools[0].radius, 0.002, 0);
  CHECK_NEAR(s.tools[0].length, 0.1, 0);
  CHECK_NEAR(s.tools[0].stiffness, 300, 0);
  CHECK_NEAR(s.tools[0].max_force, 4, 0);
  CHECK(loads(HEAD "tools: []\n", NULL) && s.ntools == 0);
  /* An organ and a tool may share a name: they are looked up apart. */
  CHECK(loads(HEAD "tools: [{name: kidney}]\n", NULL));
  /* Limits themselves are accepted. */
  CHECK(loads(HEAD "physics: {dt: 0.05, publish_hz: 240, quant_step: 1e-7, gravity: [-100, 100, 0]}\n", NULL));
  CHECK(loads(HEAD "physics: {publish_hz: 1, quant_step: 1e-2}\n", NULL));
  CHECK(loads(HEAD "    material: {stiffness: 0, damping: 0, home_stiffness: 0, home_damping: 0}\n", NULL));
  CHECK(loads(HEAD "    color: [0, 1, 1]\n", NULL));
  CHECK(loads(HEAD "tools: [{name: p, radius: 0.05, stiffness: 1e5, max_force: 100}]\n", NULL));
}

static void test_mesh_paths(void) {
  CHECK(loads(HEAD, "/b/") && !strcmp(s.organs[0].mesh, "/b/k.obj"));
  CHECK(loads(HEAD, "/") && !strcmp(s.organs[0].mesh, "/k.obj"));
  CHECK(loads(HEAD, "") && !strcmp(s.organs[0].mesh, "k.obj"));
  CHECK(loads(HEAD, "rel/dir") && !strcmp(s.organs[0].mesh, "rel/dir/k.obj"));
  CHECK(fails_with("scene: a\norgans:\n  - name: k\n    mesh: \"\"\n",
                   "t.yaml:4:", "organs[0].mesh': must not be empty"));
  /* A mesh path that fits alone but not once joined to the directory. */
  char yaml[1400];
  char longname[1020];
  memset(longname, 'm', sizeof longname - 1);
  longname[sizeof longname - 1] = '\0';
  snprintf(yaml, sizeof yaml, "scene: a\norgans:\n  - name: k\n    mesh: %s\n", longname);
  CHECK(loads(yaml, NULL) && strlen(s.organs[0].mesh) == 1019);
  CHECK(fails_with(yaml, "t.yaml:4: field 'organs[0].mesh': too long once joined", "/base"));
}

static void test_syntax_errors(void) {
  /* "mapping values are not allowed" at the second ':' of line 4. */
  CHECK(fails_with("scene: demo\norgans:\n  - name: kidney\n    mesh: a: b\n",
                   "t.yaml:4:12: YAML syntax error:", "mapping values are not allowed"));
  /* An unclosed flow list runs into the next key. */
  CHECK(fails_with(HEAD "physics:\n  gravity: [0, 0\ntools: []\n", "t.yaml:7:", "YAML syntax error"));
  /* Not UTF-8: a reader error, which libyaml reports by offset. */
  CHECK(fails_with("scene: demo\norgans:\n  - name: k\xff\n", "t.yaml:3:", "YAML syntax error"));
  CHECK(fails_with(HEAD "---\nscene: other\n", "t.yaml:5: only one YAML document", NULL));
  CHECK(fails_with("scene: &n demo\ndescription: *n\n", "t.yaml:2:14: YAML alias '*n' is not supported", NULL));
  CHECK(fails_with("- a\n- b\n", "t.yaml:1: the top level must be a mapping", "got a list"));
  CHECK(fails_with("? [a, b]\n: 1\n", "t.yaml:1:", "keys must be plain names (got a list)"));
}

static void test_empty(void) {
  CHECK(fails_with("", "t.yaml: empty scene file", NULL));
  CHECK(fails_with("# only a comment\n\n   \n", "t.yaml: empty scene file", NULL));
  CHECK(fails_with("---\n", "t.yaml: empty scene file", NULL));
}

static void test_unknown_and_duplicate_keys(void) {
  CHECK(fails_with(HEAD "    colour: [1, 0, 0]\n", "t.yaml:5: field 'organs[0].colour': unknown key",
                   "allowed: name, mesh, model, integrator, solver, position, scale, color, fixed_below, material"));
  CHECK(fails_with(HEAD "    solver:\n      substep: 3\n", "t.yaml:6: field 'organs[0].solver.substep': unknown key",
                   "allowed: substeps, iterations, cg_tolerance, cg_max_iterations, tet_size"));
  CHECK(fails_with(HEAD "    material: {bond: 3}\n", "organs[0].material.bond': unknown key",
                   "bond_k, angle_k, stretch_bend_k, distance_stiffness, volume_stiffness, distance_compliance, "
                   "volume_compliance, slope_m1, slope_m2, slope_m3, refine_area, refine_levels)"));
  CHECK(fails_with(HEAD "physic:\n  dt: 0.001\n", "t.yaml:5: field 'physic': unknown key",
                   "allowed: scene, description, physics, organs, tools"));
  CHECK(fails_with(HEAD "    material:\n      springiness: 3\n", "t.yaml:6:", "organs[0].material.springiness"));
  CHECK(fails_with(HEAD "tools:\n  - name: p\n    tip: 1\n", "t.yaml:7: field 'tools[0].tip': unknown key",
                   "allowed: name, kind, radius, length, stiffness, max_force"));
  CHECK(fails_with(HEAD "physics:\n  dt: 0.001\n  dt: 0.002\n",
                   "t.yaml:7: field 'physics.dt': duplicate key (first given at line 6)", NULL));
  CHECK(fails_with(HEAD "scene: again\n", "t.yaml:5: field 'scene': duplicate key", NULL));
}

static void test_wrong_types(void) {
  CHECK(fails_with(HEAD "physics:\n  dt: fast\n", "t.yaml:6: field 'physics.dt': must be a number (got 'fast')", NULL));
  CHECK(fails_with(HEAD "physics:\n  dt: \"0.001\"\n", "t.yaml:6:", "physics.dt': must be a number, not a quoted"));
  CHECK(fails_with(HEAD "physics:\n  dt: [0.001]\n", "t.yaml:6:", "physics.dt': must be a number (got a list)"));
  CHECK(fails_with(HEAD "physics:\n  dt:\n", "physics.dt': must be a number (got null)", NULL));
  CHECK(fails_with(HEAD "physics: 3\n", "t.yaml:5: field 'physics': must be a mapping", NULL));
  CHECK(fails_with(HEAD "    material: soft\n", "t.yaml:5:", "organs[0].material': must be a mapping"));
  CHECK(fails_with("scene: demo\norgans: kidney\n", "t.yaml:2: field 'organs': must be a list of organs", NULL));
  CHECK(fails_with("scene: demo\norgans:\n  - kidney\n", "t.yaml:3: field 'organs[0]': must be a mapping", NULL));
  CHECK(fails_with(HEAD "tools: {name: p}\n", "t.yaml:5: field 'tools': must be a list of tools", NULL));
  CHECK(fails_with("scene: [a]\norgans: []\n", "t.yaml:1: field 'scene': must be a string (got a list)", NULL));
  CHECK(fails_with(HEAD "description:\n", "field 'description': must be a string (got null)", NULL));
  CHECK(fails_with(HEAD "    scale: 1.5x\n", "t.yaml:5:", "organs[0].scale': must be a number (got '1.5x')"));
  CHECK(fails_with(HEAD "    scale: 0x10\n", "organs[0].scale': must be a number", NULL));
  CHECK(fails_with(HEAD "    scale: 1_000\n", "organs[0].scale': must be a number", NULL));
  CHECK(fails_with(HEAD "    scale: 1.5.2\n", "organs[0].scale': must be a number", NULL));
  CHECK(fails_with(HEAD "    scale: \"\\0\"\n", "organs[0].scale': must be a number", NULL));
  CHECK(fails_with(HEAD "description: \"a\\0b\"\n", "field 'description': must not contain NUL bytes", NULL));
  CHECK(fails_with(HEAD "    model: fem\n", "t.yaml:5: field 'organs[0].model': must be one of: mass_spring_surface",
                   "(got 'fem')"));
  CHECK(fails_with(HEAD "    integrator: leapfrog\n", "t.yaml:5:",
                   "organs[0].integrator': must be one of: symplectic_euler, explicit_euler, verlet, rk4, "
                   "implicit_euler, implicit_pcg (got 'leapfrog')"));
  CHECK(fails_with(HEAD "    model: fem\n",
                   "mass_spring_surface, mass_spring_tet, molecular, pbd, xpbd, vertex_based, "
                   "adaptive_mass_spring (got 'fem')",
                   NULL));
  CHECK(fails_with(HEAD "    solver: 4\n", "t.yaml:5: field 'organs[0].solver': must be a mapping", NULL));
  CHECK(fails_with(HEAD "    solver: {substeps: two}\n", "organs[0].solver.substeps': must be a number (got 'two')",
                   NULL));
  CHECK(fails_with(HEAD "    integrator: [a]\n", "organs[0].integrator': must be one of", "(got a list)"));
  CHECK(fails_with(HEAD "tools:\n  - name: s\n    kind: lancet\n", "t.yaml:7: field 'tools[0].kind'",
                   "must be one of: probe, grasper, scalpel, extractor, syringe (got 'lancet')"));
}

static void test_not_finite(void) {
  CHECK(fails_with(HEAD "physics:\n  dt: .nan\n", "t.yaml:6: field 'physics.dt': must be a finite number (got .nan)",
                   NULL));
  CHECK(fails_with(HEAD "    material:\n      stiffness: .inf\n",
                   "t.yaml:6:", "organs[0].material.stiffness': must be a finite number (got .inf)"));
  CHECK(fails_with(HEAD "physics:\n  gravity: [0, 0, -.Inf]\n", "t.yaml:6:", "physics.gravity[2]': must be a finite"));
  CHECK(fails_with(HEAD "    fixed_below: NaN\n", "t.yaml:5:", "organs[0].fixed_below': must be a finite"));
  CHECK(fails_with(HEAD "    fixed_below: -infinity\n", "organs[0].fixed_below': must be a finite", NULL));
  /* Too large for a double: strtod overflows to infinity. */
  CHECK(fails_with(HEAD "    scale: 1e999\n", "t.yaml:5:", "organs[0].scale': must be a finite number (got 1e999)"));
}

static void test_out_of_range(void) {
  /* The exact message, once, for the whole format. */
  CHECK(fails_with(HEAD "    material:\n      mass: 0.2\n      stiffness: -3\n", "", NULL));
  CHECK(!strcmp(e.msg, "t.yaml:7: field 'organs[0].material.stiffness': must be >= 0 and <= 1e+07 N/m (got -3): "
                       "stiffer than 1e7 N/m is rigid at haptic rates and overflows the stable-step estimate"));
  CHECK(fails_with(HEAD "    material: {mass: 0}\n",
                   "t.yaml:5:", "organs[0].material.mass': must be >= 0.001 and <= 20 kg (got 0)"));
  CHECK(fails_with(HEAD "    material: {damping: -0.1}\n", "organs[0].material.damping': must be >= 0", NULL));
  CHECK(fails_with(HEAD "    material: {home_stiffness: -1}\n", "organs[0].material.home_stiffness'", NULL));
  CHECK(fails_with(HEAD "    material: {home_damping: -1}\n", "organs[0].material.home_damping'", NULL));
  CHECK(fails_with(HEAD "physics:\n  dt: 0.1\n",
                   "t.yaml:6: field 'physics.dt': must be >= 1e-05 and <= 0.05 s (got 0.1)", NULL));
  CHECK(fails_with(HEAD "physics:\n  dt: 0\n", "physics.dt': must be >= 1e-05", NULL));
  CHECK(fails_with(HEAD "physics: {publish_hz: 0.5}\n", "physics.publish_hz': must be >= 1 and <= 240", NULL));
  CHECK(fails_with(HEAD "physics: {publish_hz: 241}\n", "physics.publish_hz'", "(got 241)"));
  CHECK(fails_with(HEAD "physics: {quant_step: 1e-8}\n", "physics.quant_step': must be >= 1e-07 and <= 0.01", NULL));
  CHECK(fails_with(HEAD "physics: {quant_step: 0.1}\n", "physics.quant_step'", NULL));
  CHECK(fails_with(HEAD "physics:\n  gravity:\n    - 0\n    - 200\n    - 0\n",
                   "t.yaml:8:", "physics.gravity[1]': must be >= -100 and <= 100 m/s^2 (got 200)"));
  CHECK(fails_with(HEAD "    scale: 0\n", "organs[0].scale': must be >= 1e-06", NULL));
  CHECK(fails_with(HEAD "    color: [1.5, 0, 0]\n", "t.yaml:5:", "organs[0].color[0]': must be >= 0 and <= 1"));
  CHECK(fails_with(HEAD "    color: [0, 0, -0.1]\n", "organs[0].color[2]'", NULL));
  CHECK(fails_with(HEAD "tools:\n  - name: p\n    radius: 0.06\n", "t.yaml:7: field 'tools[0].radius'",
                   "must be > 0 and <= 0.05"));
  CHECK(fails_with(HEAD "tools: [{name: p, radius: 0}]\n", "tools[0].radius'", NULL));
  CHECK(fails_with(HEAD "tools: [{name: p, length: 0}]\n", "tools[0].length': must be > 0", NULL));
  CHECK(
      fails_with(HEAD "tools: [{name: p, stiffness: 2e5}]\n", "tools[0].stiffness': must be > 0 and <= 100000", NULL));
  CHECK(fails_with(HEAD "tools: [{name: p, max_force: 0}]\n", "tools[0].max_force'", NULL));
  CHECK(fails_with(HEAD "tools: [{name: p, max_force: 101}]\n", "tools[0].max_force'", NULL));
}

/* The model-specific fields: solver settings and the extra material keys,
 * with their defaults (scene.h) and every range. */
static const char models_yaml[] = "scene: models\n"                  /* 1 */
                                  "organs:\n"                        /* 2 */
                                  "  - name: liver\n"                /* 3 */
                                  "    mesh: l.obj\n"                /* 4 */
                                  "    model: mass_spring_tet\n"     /* 5 */
                                  "    integrator: implicit_euler\n" /* 6 */
                                  "    solver:\n"                    /* 7 */
                                  "      substeps: 4\n"              /* 8 */
                                  "      iterations: 20\n"           /* 9 */
                                  "      cg_tolerance: 1e-6\n"       /* 10 */
                                  "      cg_max_iterations: 500\n"   /* 11 */
                                  "      tet_size: 0.004\n"          /* 12 */
                                  "    material:\n"                  /* 13 */
                                  "      bond_k: 40\n"               /* 14 */
                                  "      angle_k: 0.002\n"           /* 15 */
                                  "      stretch_bend_k: -0.1\n"     /* 16 */
                                  "      distance_stiffness: 0.5\n"  /* 17 */
                                  "      volume_stiffness: 0\n"      /* 18 */
                                  "      distance_compliance: 0\n"   /* 19 */
                                  "      volume_compliance: 2e-7\n"  /* 20 */
                                  "      slope_m1: 0.9\n"            /* 21 */
                                  "      slope_m2: 0.95\n"           /* 22 */
                                  "      slope_m3: 0.1\n"            /* 23 */
                                  "      refine_area: 1e-5\n"        /* 24 */
                                  "      refine_levels: 4\n";        /* 25 */

static void test_model_fields(void) {
  CHECK(loads(models_yaml, NULL));
  const scene_organ_t *o = &s.organs[0];
  CHECK(!strcmp(o->model, "mass_spring_tet"));
  CHECK(!strcmp(o->integrator, "implicit_euler"));
  CHECK(o->solver.substeps == 4 && o->solver.iterations == 20 && o->solver.cg_max_iterations == 500);
  CHECK_NEAR(o->solver.cg_tolerance, 1e-6, 1e-20);
  CHECK_NEAR(o->solver.tet_size, 0.004, 1e-18);
  const scene_material_t *m = &o->material;
  CHECK_NEAR(m->bond_k, 40, 0);
  CHECK_NEAR(m->angle_k, 0.002, 1e-18);
  CHECK_NEAR(m->stretch_bend_k, -0.1, 1e-16);
  CHECK_NEAR(m->distance_stiffness, 0.5, 0);
  CHECK_NEAR(m->volume_stiffness, 0, 0);
  CHECK_NEAR(m->distance_compliance, 0, 0);
  CHECK_NEAR(m->volume_compliance, 2e-7, 1e-22);
  /* Slopes out of order are fine for a model that does not use them. */
  CHECK_NEAR(m->slope_m1, 0.9, 1e-16);
  CHECK_NEAR(m->slope_m2, 0.95, 1e-16);
  CHECK_NEAR(m->slope_m3, 0.1, 1e-16);
  CHECK_NEAR(m->refine_area, 1e-5, 1e-20);
  CHECK(m->refine_levels == 4);
  /* Defaults: every model and integrator name is accepted; the rest as in scene.h. */
  static const char *const models[] = {"mass_spring_surface", "mass_spring_tet",     "molecular", "pbd", "xpbd",
                                       "vertex_based",        "adaptive_mass_spring"};
  static const char *const integrators[] = {"explicit_euler", "symplectic_euler", "verlet", "rk4", "implicit_euler"};
  char yaml[256];
  for (size_t i = 0; i < sizeof models / sizeof models[0]; i++) {
    snprintf(yaml, sizeof yaml, HEAD "    model: %s\n", models[i]);
    CHECK(loads(yaml, NULL) && !strcmp(s.organs[0].model, models[i]));
  }
  for (size_t i = 0; i < sizeof integrators / sizeof integrators[0]; i++) {
    snprintf(yaml, sizeof yaml, HEAD "    integrator: %s\n", integrators[i]);
    CHECK(loads(yaml, NULL) && !strcmp(s.organs[0].integrator, integrators[i]));
  }
  /* xpbd has its own default iteration count; pbd keeps 10; a given count wins. */
  CHECK(loads(HEAD "    model: xpbd\n", NULL) && s.organs[0].solver.iterations == SCENE_XPBD_ITERATIONS);
  CHECK(loads(HEAD "    model: pbd\n", NULL) && s.organs[0].solver.iterations == 10);
  CHECK(loads(HEAD "    model: xpbd\n    solver: {iterations: 10}\n", NULL) && s.organs[0].solver.iterations == 10);
  CHECK(loads(HEAD, NULL));
  o = &s.organs[0];
  m = &o->material;
  CHECK(o->solver.substeps == 0 && o->solver.iterations == 10 && o->solver.cg_max_iterations == 200);
  CHECK_NEAR(o->solver.cg_tolerance, 1e-3, 0);
  CHECK_NEAR(o->solver.tet_size, 0, 0);
  CHECK_NEAR(m->bond_k, 30, 0);
  CHECK_NEAR(m->angle_k, 1e-3, 0);
  CHECK_NEAR(m->stretch_bend_k, 0, 0);
  CHECK_NEAR(m->distance_stiffness, 1, 0);
  CHECK_NEAR(m->volume_stiffness, 1, 0);
  CHECK_NEAR(m->distance_compliance, 1e-4, 0);
  CHECK_NEAR(m->volume_compliance, 1e-6, 0);
  CHECK_NEAR(m->slope_m1, 1, 0);
  CHECK_NEAR(m->slope_m2, 0.6, 0);
  CHECK_NEAR(m->slope_m3, 0.3, 0);
  CHECK_NEAR(m->refine_area, 2e-5, 0);
  CHECK(m->refine_levels == 2);
  /* Limits themselves load. */
  CHECK(loads(HEAD "    solver: {substeps: 256, iterations: 1000, cg_tolerance: 0.1, cg_max_iterations: 10000, "
                   "tet_size: 0.1}\n",
              NULL));
  CHECK(loads(HEAD "    solver: {substeps: 0, iterations: 1, cg_tolerance: 1e-12, cg_max_iterations: 1, "
                   "tet_size: 1e-4}\n",
              NULL));
  CHECK(loads(HEAD "    material: {distance_stiffness: 1, volume_stiffness: 1, refine_levels: 1}\n", NULL));
}

static void test_model_field_ranges(void) {
  CHECK(fails_with(HEAD "    solver:\n      substeps: 257\n",
                   "t.yaml:6: field 'organs[0].solver.substeps': must be >= 0 and <= 256 (got 257)", NULL));
  CHECK(fails_with(HEAD "    solver: {substeps: -1}\n", "organs[0].solver.substeps': must be >= 0", NULL));
  CHECK(fails_with(HEAD "    solver: {substeps: 2.5}\n",
                   "t.yaml:5: field 'organs[0].solver.substeps': must be a whole number (got 2.5)", NULL));
  CHECK(
      fails_with(HEAD "    solver: {iterations: 0}\n", "organs[0].solver.iterations': must be >= 1 and <= 1000", NULL));
  CHECK(fails_with(HEAD "    solver: {iterations: 1001}\n", "organs[0].solver.iterations'", "(got 1001)"));
  CHECK(fails_with(HEAD "    solver: {cg_tolerance: 1e-13}\n",
                   "organs[0].solver.cg_tolerance': must be >= 1e-12 and <= 0.1 (got 1e-13)", NULL));
  CHECK(fails_with(HEAD "    solver: {cg_tolerance: 0.2}\n", "organs[0].solver.cg_tolerance'", NULL));
  CHECK(fails_with(HEAD "    solver: {cg_max_iterations: 0}\n",
                   "organs[0].solver.cg_max_iterations': must be >= 1 and <= 10000", NULL));
  CHECK(fails_with(HEAD "    solver: {cg_max_iterations: 10001}\n", "organs[0].solver.cg_max_iterations'", NULL));
  CHECK(fails_with(HEAD "    solver: {cg_max_iterations: 1e3x}\n", "must be a number", NULL));
  CHECK(fails_with(HEAD "    solver:\n      tet_size: 5e-5\n",
                   "t.yaml:6: field 'organs[0].solver.tet_size': must be 0 (automatic) or >= 0.0001 and <= 0.1 "
                   "(got 5e-5)",
                   NULL));
  CHECK(fails_with(HEAD "    solver: {tet_size: 0.2}\n", "organs[0].solver.tet_size': must be >= 0 and <= 0.1", NULL));
  CHECK(fails_with(HEAD "    solver: {tet_size: -0.01}\n", "organs[0].solver.tet_size'", NULL));
  CHECK(fails_with(HEAD "    material: {bond_k: -1}\n", "organs[0].material.bond_k': must be >= 0", NULL));
  CHECK(fails_with(HEAD "    material: {angle_k: -1}\n", "organs[0].material.angle_k': must be >= 0", NULL));
  CHECK(fails_with(HEAD "    material: {stretch_bend_k: .nan}\n",
                   "organs[0].material.stretch_bend_k': must be a finite", NULL));
  CHECK(fails_with(HEAD "    material: {distance_stiffness: 1.5}\n",
                   "organs[0].material.distance_stiffness': must be >= 0 and <= 1 (got 1.5)", NULL));
  CHECK(fails_with(HEAD "    material: {volume_stiffness: -0.1}\n", "organs[0].material.volume_stiffness'", NULL));
  CHECK(fails_with(HEAD "    material: {distance_compliance: -1e-5}\n",
                   "organs[0].material.distance_compliance': must be >= 0", NULL));
  CHECK(fails_with(HEAD "    material: {volume_compliance: -1}\n", "organs[0].material.volume_compliance'", NULL));
  CHECK(fails_with(HEAD "    material: {slope_m1: 0}\n", "organs[0].material.slope_m1': must be > 0", NULL));
  CHECK(fails_with(HEAD "    material: {slope_m2: -1}\n", "organs[0].material.slope_m2': must be > 0", NULL));
  CHECK(fails_with(HEAD "    material: {slope_m3: 0}\n", "organs[0].material.slope_m3': must be > 0", NULL));
  CHECK(fails_with(HEAD "    material: {refine_area: 0}\n", "organs[0].material.refine_area': must be > 0", NULL));
  CHECK(fails_with(HEAD "    material: {refine_levels: 0}\n",
                   "organs[0].material.refine_levels': must be >= 1 and <= 4 (got 0)", NULL));
  CHECK(fails_with(HEAD "    material: {refine_levels: 5}\n", "organs[0].material.refine_levels'", NULL));
  CHECK(fails_with(HEAD "    material: {refine_levels: 1.5}\n", "organs[0].material.refine_levels': must be a whole",
                   NULL));
}

/* Checks across fields: the molecular energy must be positive definite and
 * the vertex-based slopes must fall off from the touched node outwards. */
static void test_model_consistency(void) {
  /* k_r k_theta = 30 * 0.001 = 0.03 <= 2 k_sb^2 = 0.08: refused at the
   * coupling's line, with the numbers. */
  CHECK(fails_with(HEAD "    model: molecular\n    material:\n      bond_k: 30\n      angle_k: 0.001\n"
                        "      stretch_bend_k: 0.2\n",
                   "", NULL));
  CHECK(!strcmp(e.msg, "t.yaml:9: field 'organs[0].material.stretch_bend_k': the molecular model needs bond_k * "
                       "angle_k > 2 * stretch_bend_k^2 for a positive-definite energy (got 30 * 0.001 = 0.03 <= "
                       "2 * 0.2^2 = 0.08)"));
  /* Equality is not enough; a negative coupling counts by its square. */
  CHECK(fails_with(HEAD "    model: molecular\n    material: {bond_k: 8, angle_k: 0.01, stretch_bend_k: -0.2}\n",
                   "t.yaml:6: field 'organs[0].material.stretch_bend_k'",
                   "(got 8 * 0.01 = 0.08 <= 2 * (-0.2)^2 = 0.08)"));
  /* Without a coupling the fault is the angle or bond term that was given. */
  CHECK(fails_with(HEAD "    model: molecular\n    material:\n      angle_k: 0\n",
                   "t.yaml:7: field 'organs[0].material.angle_k'", "(got 30 * 0 = 0 <= 2 * 0^2 = 0)"));
  CHECK(fails_with(HEAD "    model: molecular\n    material:\n      bond_k: 0\n",
                   "t.yaml:7: field 'organs[0].material.bond_k'", NULL));
  CHECK(loads(HEAD "    model: molecular\n", NULL));
  CHECK(loads(HEAD "    model: molecular\n    material: {bond_k: 30, angle_k: 0.001, stretch_bend_k: 0.12}\n", NULL));
  CHECK(loads(HEAD "    model: pbd\n    material: {bond_k: 30, angle_k: 0.001, stretch_bend_k: 0.2}\n", NULL));
  /* The material may come before the model line: still checked. */
  CHECK(fails_with(HEAD "    material: {stretch_bend_k: 1}\n    model: molecular\n", "t.yaml:5:", "stretch_bend_k"));

  CHECK(fails_with(HEAD "    model: vertex_based\n    material:\n      slope_m1: 0.5\n",
                   "t.yaml:7: field 'organs[0].material.slope_m1': the vertex_based model needs slope_m1 > slope_m2 > "
                   "slope_m3 (got 0.5, 0.6, 0.3)",
                   NULL));
  CHECK(fails_with(HEAD "    model: vertex_based\n    material: {slope_m1: 1, slope_m2: 0.5, slope_m3: 0.5}\n",
                   "t.yaml:6: field 'organs[0].material.slope_m3'", "(got 1, 0.5, 0.5)"));
  CHECK(fails_with(HEAD "    model: vertex_based\n    material: {slope_m2: 2}\n", "organs[0].material.slope_m2'",
                   "(got 1, 2, 0.3)"));
  CHECK(loads(HEAD "    model: vertex_based\n    material: {slope_m1: 2, slope_m2: 1, slope_m3: 0.5}\n", NULL));
  CHECK(loads(HEAD "    model: vertex_based\n", NULL));
}

static void test_missing_required(void) {
  CHECK(fails_with("scene: demo\norgans:\n  - name: kidney\n    scale: 2\n",
                   "t.yaml:3: field 'organs[0].mesh': required field missing", NULL));
  CHECK(fails_with("scene: demo\norgans:\n  - name: a\n    mesh: a.obj\n  - mesh: b.obj\n",
                   "t.yaml:5: field 'organs[1].name': required field missing", NULL));
  CHECK(fails_with("# a scene\norgans:\n  - name: a\n    mesh: a.obj\n",
                   "t.yaml:2: field 'scene': required field missing", NULL));
  CHECK(fails_with("scene: demo\n", "t.yaml:1: field 'organs': required field missing", NULL));
  CHECK(fails_with(HEAD "tools:\n  - kind: probe\n", "t.yaml:6: field 'tools[0].name': required field missing", NULL));
  CHECK(fails_with("scene: demo\norgans: []\n", "t.yaml:2: field 'organs': needs at least 1 organ (got 0)", NULL));
}

static void test_counts_and_names(void) {
  /* 17 organs, one per line from line 3: the 17th is on line 19. */
  char yaml[4096];
  size_t k = (size_t)snprintf(yaml, sizeof yaml, "scene: many\norgans:\n");
  for (int i = 0; i < 17; i++) k += (size_t)snprintf(yaml + k, sizeof yaml - k, "  - {name: o%d, mesh: o.obj}\n", i);
  CHECK(fails_with(yaml, "t.yaml:19: field 'organs': too many organs (17, max 16)", NULL));
  /* 16 is the limit and loads. */
  *strstr(yaml, "  - {name: o16") = '\0';
  CHECK(loads(yaml, NULL) && s.norgans == 16 && s.organs[15].line == 18);

  k = (size_t)snprintf(yaml, sizeof yaml, HEAD "tools:\n");
  for (int i = 0; i < 9; i++) k += (size_t)snprintf(yaml + k, sizeof yaml - k, "  - name: t%d\n", i);
  CHECK(fails_with(yaml, "t.yaml:14: field 'tools': too many tools (9, max 8)", NULL));
  *strstr(yaml, "  - name: t8") = '\0';
  CHECK(loads(yaml, NULL) && s.ntools == 8);

  CHECK(fails_with(HEAD "  - name: liver\n    mesh: l.obj\n  - name: kidney\n    mesh: k2.obj\n",
                   "t.yaml:7: field 'organs[2].name': duplicate organ name 'kidney'",
                   "first used by organs[0] at line 3"));
  CHECK(fails_with(HEAD "tools:\n  - name: p\n  - name: p\n",
                   "t.yaml:7: field 'tools[1].name': duplicate tool name 'p'", NULL));
  CHECK(fails_with("scene: demo\norgans:\n  - name: kid ney\n    mesh: k.obj\n",
                   "t.yaml:3:", "organs[0].name': may contain only letters, digits, '_' and '-' (got 'kid ney')"));
  CHECK(
      fails_with("scene: demo\norgans:\n  - name: a/b\n    mesh: k.obj\n", "organs[0].name': may contain only", NULL));
  CHECK(fails_with("scene: demo\norgans:\n  - name: \"\"\n    mesh: k.obj\n",
                   "t.yaml:3:", "organs[0].name': must not be empty"));
  CHECK(fails_with(HEAD "tools: [{name: \"p 1\"}]\n", "tools[0].name': may contain only", NULL));
  CHECK(
      fails_with("scene: my scene\norgans: [{name: a, mesh: a.obj}]\n", "t.yaml:1: field 'scene': may contain", NULL));
}

static void test_vectors(void) {
  CHECK(fails_with(HEAD "    position: [0.1, 0.2]\n",
                   "t.yaml:5: field 'organs[0].position': must be a list of 3 numbers [x, y, z] (got 2 items)", NULL));
  CHECK(fails_with(HEAD "    position: [0, 0, 0, 0]\n", "organs[0].position'", "(got 4 items)"));
  CHECK(fails_with(HEAD "    position: 0.1\n", "organs[0].position'", "(got a single value)"));
  CHECK(fails_with(HEAD "physics:\n  gravity: {x: 0}\n", "t.yaml:6: field 'physics.gravity'", "(got a mapping)"));
  CHECK(fails_with(HEAD "    color: [1, red, 0]\n", "organs[0].color[1]': must be a number (got 'red')", NULL));
  CHECK(fails_with(HEAD "    position: [0, [1], 0]\n", "organs[0].position[1]': must be a number (got a list)", NULL));
}

static void test_string_lengths(void) {
  char name[SCENE_NAME_LEN + 1], yaml[2048];
  memset(name, 'n', SCENE_NAME_LEN - 1); /* 63 bytes: the longest that fits */
  name[SCENE_NAME_LEN - 1] = '\0';
  snprintf(yaml, sizeof yaml, "scene: demo\norgans:\n  - name: %s\n    mesh: k.obj\n", name);
  CHECK(loads(yaml, NULL) && strlen(s.organs[0].name) == SCENE_NAME_LEN - 1);
  strcat(name, "n");
  snprintf(yaml, sizeof yaml, "scene: demo\norgans:\n  - name: %s\n    mesh: k.obj\n", name);
  CHECK(fails_with(yaml, "t.yaml:3: field 'organs[0].name': too long (64 bytes, max 63)", NULL));
  snprintf(yaml, sizeof yaml, "scene: %s\norgans: [{name: a, mesh: a.obj}]\n", name);
  CHECK(fails_with(yaml, "t.yaml:1: field 'scene': too long", NULL));

  char desc[300];
  memset(desc, 'd', 255);
  desc[255] = '\0';
  snprintf(yaml, sizeof yaml, HEAD "description: %s\n", desc);
  CHECK(loads(yaml, NULL) && strlen(s.description) == 255);
  strcat(desc, "d");
  snprintf(yaml, sizeof yaml, HEAD "description: %s\n", desc);
  CHECK(fails_with(yaml, "t.yaml:5: field 'description': too long (256 bytes, max 255)", NULL));
}

static void test_limits(void) {
  /* Depth: the root mapping is level 1, so 15 nested lists load as a (wrong)
   * description, and 16 exceed the 16 levels allowed. */
  char yaml[256];
  snprintf(yaml, sizeof yaml, HEAD "description: %.15s%.15s\n", "[[[[[[[[[[[[[[[", "]]]]]]]]]]]]]]]");
  CHECK(fails_with(yaml, "field 'description': must be a string (got a list)", NULL));
  snprintf(yaml, sizeof yaml, HEAD "description: %.16s%.16s\n", "[[[[[[[[[[[[[[[[", "]]]]]]]]]]]]]]]]");
  CHECK(fails_with(yaml, "t.yaml:5:", "nesting deeper than 16 levels"));

  /* Size: over 1 MiB is refused before parsing. */
  size_t big = (1u << 20) + 1;
  char *text = malloc(big + 1);
  CHECK(text != NULL);
  if (!text) return;
  memset(text, '#', big);
  text[big] = '\0';
  CHECK(fails_with(text, "t.yaml: scene text too large", NULL));

  /* Node count: a long flat list trips the cap with a position. */
  size_t k = (size_t)snprintf(text, big, HEAD "description: [");
  for (int i = 0; i < 25000; i++) k += (size_t)snprintf(text + k, big - k, "0,");
  snprintf(text + k, big - k, "0]\n");
  CHECK(fails_with(text, "t.yaml:5:", "too many YAML nodes"));
  free(text);

  CHECK(scene_load_string(NULL, "x", NULL, &s, &e) == -1 && strstr(e.msg, "NULL"));
}

static int write_file(const char *path, const char *text, size_t len) {
  FILE *f = fopen(path, "wb");
  if (!f) return -1;
  size_t n = fwrite(text, 1, len, f);
  return (fclose(f) == 0 && n == len) ? 0 : -1;
}

static void test_files(void) {
  char dir[] = "/tmp/test_scene.XXXXXX", path[256], empty[256], big[256], cwd[1024];
  CHECK(mkdtemp(dir) != NULL);
  snprintf(path, sizeof path, "%s/s.yaml", dir);
  snprintf(empty, sizeof empty, "%s/empty.yaml", dir);
  snprintf(big, sizeof big, "%s/big.yaml", dir);
  CHECK(write_file(path, HEAD "tools: [{name: p}]\n", strlen(HEAD "tools: [{name: p}]\n")) == 0);
  CHECK(write_file(empty, "", 0) == 0);

  CHECK(scene_load(path, &s, &e) == 0);
  CHECK(!strcmp(s.path, path));
  char want[600];
  snprintf(want, sizeof want, "%s/k.obj", dir);
  CHECK(!strcmp(s.organs[0].mesh, want));
  CHECK(s.organs[0].line == 3 && s.tools[0].line == 5);

  char missing[300];
  snprintf(missing, sizeof missing, "%s/nope.yaml", dir);
  CHECK(scene_load(missing, &s, &e) == -1);
  snprintf(want, sizeof want, "%s: cannot open: No such file or directory", missing);
  CHECK(!strcmp(e.msg, want));

  CHECK(scene_load(empty, &s, &e) == -1);
  snprintf(want, sizeof want, "%s: empty scene file", empty);
  CHECK(!strcmp(e.msg, want));

  CHECK(scene_load(dir, &s, &e) == -1 && strstr(e.msg, ": cannot read:") && strstr(e.msg, dir));

  /* Errors in a file name the file path, not a stand-in. */
  CHECK(write_file(path, HEAD "    scale: -1\n", strlen(HEAD "    scale: -1\n")) == 0);
  CHECK(scene_load(path, &s, &e) == -1);
  snprintf(want, sizeof want,
           "%s:5: field 'organs[0].scale': must be >= 1e-06 and <= 1e+06 (got -1): a unit conversion (um, mm, cm to m) "
           "with room; the scaled mesh is checked too",
           path);
  CHECK(!strcmp(e.msg, want));

  size_t n = (1u << 20) + 1;
  char *text = malloc(n);
  CHECK(text != NULL);
  if (text) {
    memset(text, '#', n);
    CHECK(write_file(big, text, n) == 0);
    CHECK(scene_load(big, &s, &e) == -1 && strstr(e.msg, "scene file too large"));
    CHECK(write_file(big, text, n - 1) == 0); /* exactly 1 MiB of comment: read, then empty */
    CHECK(scene_load(big, &s, &e) == -1 && strstr(e.msg, "empty scene file"));
    free(text);
  }

  /* A bare file name: the mesh stays relative to the cwd, its directory. */
  CHECK(write_file(path, HEAD, strlen(HEAD)) == 0);
  CHECK(getcwd(cwd, sizeof cwd) != NULL);
  CHECK(chdir(dir) == 0);
  CHECK(scene_load("s.yaml", &s, &e) == 0 && !strcmp(s.organs[0].mesh, "k.obj") && !strcmp(s.path, "s.yaml"));
  CHECK(chdir(cwd) == 0);

  remove(path);
  remove(empty);
  remove(big);
  CHECK(rmdir(dir) == 0);
}

/* The shipped example is the format's documentation: it must stay valid. */
static void test_default_asset(void) {
  const char *src = getenv("VISCERA_SOURCE_DIR");
  CHECK(src != NULL); /* set by ctest */
  if (!src) return;
  char path[1024], want[1100];
  snprintf(path, sizeof path, "%s", test_asset("scenes/default.yaml"));
  if (scene_load(path, &s, &e) != 0) {
    fprintf(stderr, "  %s\n", e.msg);
    CHECK(!"default.yaml loads");
    return;
  }
  CHECK(!strcmp(s.name, "kidney-palpation"));
  CHECK_NEAR(s.dt, 0.001, 0);
  CHECK_NEAR(s.publish_hz, 30, 0);
  CHECK(s.norgans == 1 && s.ntools == 1);
  const scene_organ_t *o = &s.organs[0];
  snprintf(want, sizeof want, "%s/assets/scenes/../meshes/kidney.obj", src);
  CHECK(!strcmp(o->mesh, want));
  CHECK(!strcmp(o->model, "mass_spring_surface"));
  CHECK(!strcmp(o->integrator, "symplectic_euler"));
  CHECK_NEAR(o->material.mass, 0.15, 1e-15);
  CHECK_NEAR(o->material.stiffness, 30, 0);
  CHECK_NEAR(o->material.damping, 0.02, 1e-15);
  CHECK_NEAR(o->material.home_stiffness, 30, 0);
  CHECK_NEAR(o->material.home_damping, 0.005, 1e-15);
  CHECK(o->color[0] > o->color[1] && o->color[0] > o->color[2]); /* reddish */
  const scene_tool_t *t = &s.tools[0];
  CHECK(!strcmp(t->kind, "probe"));
  CHECK_NEAR(t->radius, 0.003, 1e-15);
  CHECK_NEAR(t->stiffness, 400, 0);
  CHECK_NEAR(t->max_force, 4, 0);
  CHECK_NEAR(t->st, 0.5, 1e-15);
  CHECK_NEAR(t->mpf, 0.8, 1e-15);
  CHECK_NEAR(t->sft, 1.5, 1e-15);
}

/* Palpation thresholds (docs/methods.md B ch. 6): optional, each key too, in the order
 * st < mpf <= sft <= max_force, refused at the offending line. */
static void test_thresholds(void) {
  /* None given: all unset. */
  CHECK(loads(HEAD "tools: [{name: p}]\n", NULL));
  CHECK(s.tools[0].st == 0 && s.tools[0].mpf == 0 && s.tools[0].sft == 0);
  /* Flow and block forms. */
  CHECK(loads(HEAD "tools: [{name: p, thresholds: {sft: 1.5, st: 0.6, mpf: 0.9}}]\n", NULL));
  CHECK_NEAR(s.tools[0].st, 0.6, 1e-15);
  CHECK_NEAR(s.tools[0].mpf, 0.9, 1e-15);
  CHECK_NEAR(s.tools[0].sft, 1.5, 1e-15);
  CHECK(loads(HEAD "tools:\n  - name: p\n    max_force: 2\n    thresholds:\n      st: 0.5\n      sft: 2\n", NULL));
  CHECK_NEAR(s.tools[0].st, 0.5, 0);
  CHECK(s.tools[0].mpf == 0);
  CHECK_NEAR(s.tools[0].sft, 2, 0);
  /* A subset is fine; mpf may equal sft. */
  CHECK(loads(HEAD "tools: [{name: p, thresholds: {mpf: 1}}]\n", NULL) && s.tools[0].mpf == 1 && s.tools[0].st == 0);
  CHECK(loads(HEAD "tools: [{name: p, thresholds: {mpf: 1, sft: 1}}]\n", NULL));
  CHECK(loads(HEAD "tools: [{name: p, thresholds: {}}]\n", NULL) && s.tools[0].sft == 0);
  /* Errors with line and field. */
  CHECK(fails_with(HEAD "tools:\n  - name: p\n    thresholds:\n      st: 0.5\n      stf: 1\n",
                   "t.yaml:9: field 'tools[0].thresholds.stf': unknown key", "allowed: st, mpf, sft"));
  CHECK(fails_with(HEAD "tools:\n  - name: p\n    thresholds:\n      st: 0\n",
                   "t.yaml:8: field 'tools[0].thresholds.st': must be > 0", NULL));
  CHECK(fails_with(HEAD "tools:\n  - name: p\n    thresholds:\n      sft: -1\n",
                   "t.yaml:8: field 'tools[0].thresholds.sft'", NULL));
  CHECK(fails_with(HEAD "tools:\n  - name: p\n    thresholds:\n      st: abc\n",
                   "t.yaml:8: field 'tools[0].thresholds.st'", NULL));
  CHECK(fails_with(HEAD "tools:\n  - name: p\n    thresholds: 1\n",
                   "t.yaml:7: field 'tools[0].thresholds': must be a mapping", NULL));
  /* Above max_force, whichever order the keys come in. */
  CHECK(fails_with(HEAD "tools:\n  - name: p\n    thresholds:\n      sft: 5\n    max_force: 4\n",
                   "t.yaml:8: field 'tools[0].thresholds.sft': must be <= the tool's max_force 4 N (got 5)", NULL));
  /* Out of order: reported at the higher threshold's line. */
  CHECK(fails_with(HEAD "tools:\n  - name: p\n    thresholds:\n      st: 0.6\n      mpf: 0.5\n",
                   "t.yaml:9: field 'tools[0].thresholds.mpf': must be > st 0.6 N", "st < mpf <= sft"));
  CHECK(fails_with(HEAD "tools:\n  - name: p\n    thresholds:\n      st: 0.6\n      mpf: 0.6\n",
                   "t.yaml:9: field 'tools[0].thresholds.mpf': must be > st", NULL));
  CHECK(fails_with(HEAD "tools:\n  - name: p\n    thresholds:\n      sft: 0.8\n      mpf: 0.9\n",
                   "t.yaml:8: field 'tools[0].thresholds.sft': must be >= mpf 0.9 N", NULL));
  CHECK(fails_with(HEAD "tools:\n  - name: p\n    thresholds:\n      st: 1\n      sft: 1\n",
                   "t.yaml:9: field 'tools[0].thresholds.sft': must be > st 1 N", NULL));
  CHECK(fails_with(HEAD "tools:\n  - name: p\n    thresholds:\n      st: 1\n      st: 0.5\n",
                   "t.yaml:9: field 'tools[0].thresholds.st': duplicate key", NULL));
}

int main(void) {
  test_full_scene();
  test_defaults();
  test_mesh_paths();
  test_syntax_errors();
  test_empty();
  test_unknown_and_duplicate_keys();
  test_wrong_types();
  test_not_finite();
  test_out_of_range();
  test_model_fields();
  test_model_field_ranges();
  test_model_consistency();
  test_missing_required();
  test_counts_and_names();
  test_vectors();
  test_string_lengths();
  test_limits();
  test_files();
  test_default_asset();
  test_thresholds();
  return check_report("test_scene");
}
