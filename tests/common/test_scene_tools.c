/* SPDX-License-Identifier: Apache-2.0 */
/* test_scene_tools: the scene keys of issue 4 (tool kinds and capabilities,
 * friction, objects, tasks): values and defaults are read, and every
 * mistake is refused with the right line and field. */
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "scene.h"
#include "scene_expect.h"

static scene_t s; /* large: keep it off the stack */
static verr_t e;

/* See scene_expect.h. */
static int fails_with(const char *yaml, const char *a, const char *b) { return scene_fails_with(&s, &e, yaml, a, b); }
static int loads(const char *yaml) { return scene_loads(&s, &e, yaml, "/base"); }

/* Lines 1-6: two organs. */
#define HEAD                                                                                                           \
  "scene: demo\n"                                                                                                      \
  "organs:\n"                                                                                                          \
  "  - name: kidney\n"                                                                                                 \
  "    mesh: k.obj\n"                                                                                                  \
  "  - name: spleen\n"                                                                                                 \
  "    mesh: s.obj\n"

static const char full[] = HEAD                                                                   /* 1-6 */
    "tools:\n"                                                                                    /* 7 */
    "  - {name: p, kind: probe, friction: 0.4}\n"                                                 /* 8 */
    "  - {name: g, kind: grasper, radius: 0.002, grasp_radius: 0.005, jaw_opening: 0.012}\n"      /* 9 */
    "  - {name: x, kind: extractor, radius: 0.0015}\n"                                            /* 10 */
    "  - {name: c, kind: scalpel}\n"                                                              /* 11 */
    "  - {name: y, kind: syringe}\n"                                                              /* 12 */
    "objects:\n"                                                                                  /* 13 */
    "  - {name: stone, radius: 0.004, position: [0.01, 0, 0.02], organ: spleen}\n"                /* 14 */
    "tasks:\n"                                                                                    /* 15 */
    "  - {name: out, kind: stone_removal, tool: x, object: stone}\n"                              /* 16 */
    "  - {name: find, kind: palpate_target, tool: p, target: [0, 0.01, 0.03]}\n"                  /* 17 */
    "  - {name: pull, kind: grasp_pull, tool: g, distance: 0.02}\n"                               /* 18 */
    "  - {name: find2, kind: palpate_target, tool: y, target: [0, 0, 0], target_radius: 0.01}\n"; /* 19 */

static void test_full(void) {
  CHECK(loads(full));
  CHECK(s.ntools == 5);
  CHECK(!strcmp(s.tools[0].kind, "probe"));
  CHECK_NEAR(s.tools[0].friction, 0.4, 1e-15);
  CHECK_NEAR(s.tools[0].grasp_radius, 0, 0); /* no jaws */
  CHECK(!strcmp(s.tools[1].kind, "grasper"));
  CHECK_NEAR(s.tools[1].grasp_radius, 0.005, 1e-15);
  CHECK_NEAR(s.tools[1].jaw_opening, 0.012, 1e-15);
  CHECK_NEAR(s.tools[1].friction, 0, 0);
  CHECK(!strcmp(s.tools[2].kind, "extractor"));
  CHECK_NEAR(s.tools[2].grasp_radius, 0.003, 1e-15); /* default: 2 x radius */
  CHECK_NEAR(s.tools[2].jaw_opening, 0, 0);
  CHECK(!strcmp(s.tools[3].kind, "scalpel"));
  CHECK(!strcmp(s.tools[4].kind, "syringe"));
  CHECK(s.nobjects == 1);
  const scene_object_t *o = &s.objects[0];
  CHECK(!strcmp(o->name, "stone") && !strcmp(o->kind, "stone"));
  CHECK_NEAR(o->radius, 0.004, 1e-15);
  CHECK_NEAR(o->position[0], 0.01, 1e-15);
  CHECK_NEAR(o->position[2], 0.02, 1e-15);
  CHECK(o->organ == 1);
  CHECK(o->line == 14);
  CHECK_NEAR(o->color[0], 0.85, 1e-6);
  CHECK(s.ntasks == 4);
  CHECK(!strcmp(s.tasks[0].kind, "stone_removal") && s.tasks[0].tool == 2 && s.tasks[0].object == 0);
  CHECK(!strcmp(s.tasks[1].kind, "palpate_target") && s.tasks[1].tool == 0 && s.tasks[1].object == -1);
  CHECK_NEAR(s.tasks[1].target[1], 0.01, 1e-15);
  CHECK_NEAR(s.tasks[1].target_radius, 0.005, 1e-15); /* default */
  CHECK(!strcmp(s.tasks[2].kind, "grasp_pull") && s.tasks[2].tool == 1);
  CHECK_NEAR(s.tasks[2].distance, 0.02, 1e-15);
  CHECK_NEAR(s.tasks[3].target_radius, 0.01, 1e-15);
  CHECK(s.tasks[3].line == 19);
}

static void test_defaults(void) {
  CHECK(loads(HEAD "tools:\n  - {name: g, kind: grasper, radius: 0.003}\n"));
  CHECK_NEAR(s.tools[0].grasp_radius, 0.006, 1e-15);
  CHECK_NEAR(s.tools[0].jaw_opening, 0.012, 1e-15);
  CHECK(s.nobjects == 0 && s.ntasks == 0);
  CHECK(loads(HEAD "tools:\n  - {name: p}\n"));
  CHECK(!strcmp(s.tools[0].kind, "probe"));
  CHECK_NEAR(s.tools[0].friction, 0, 0);
}

static void test_tool_errors(void) {
  CHECK(fails_with(HEAD "tools:\n  - {name: p, kind: forceps}\n", "t.yaml:8: field 'tools[0].kind'",
                   "must be one of: probe, grasper, scalpel, extractor, syringe (got 'forceps')"));
  CHECK(fails_with(HEAD "tools:\n  - {name: p, grasp_radius: 0.004}\n", "t.yaml:8: field 'tools[0].grasp_radius'",
                   "only a grasper or an extractor grasps (this tool is a probe)"));
  CHECK(fails_with(HEAD "tools:\n  - {name: p, kind: extractor, jaw_opening: 0.004}\n",
                   "t.yaml:8: field 'tools[0].jaw_opening'", "only a grasper has jaws"));
  CHECK(fails_with(HEAD "tools:\n  - name: p\n    friction: -0.1\n", "t.yaml:9: field 'tools[0].friction'",
                   "must be >= 0 and <= 2"));
  CHECK(fails_with(HEAD "tools:\n  - {name: p, kind: grasper, grasp_radius: 0}\n",
                   "t.yaml:8: field 'tools[0].grasp_radius'", "must be > 0"));
}

#define TOOLS "tools:\n  - {name: p}\n  - {name: g, kind: grasper}\n  - {name: x, kind: extractor}\n" /* 7-10 */

static void test_object_errors(void) {
  CHECK(fails_with(HEAD "objects:\n  - {name: s, radius: 0.004, position: [0, 0, 0], organ: liver}\n",
                   "t.yaml:8: field 'objects[0].organ'", "no organ named 'liver' (known: kidney, spleen)"));
  CHECK(fails_with(HEAD "objects:\n  - {name: s, position: [0, 0, 0], organ: kidney}\n",
                   "t.yaml:8: field 'objects[0].radius'", "required field missing"));
  CHECK(fails_with(HEAD "objects:\n  - {name: s, radius: 0.004, organ: kidney}\n",
                   "t.yaml:8: field 'objects[0].position'", "required field missing"));
  CHECK(fails_with(HEAD "objects:\n  - {name: s, radius: 0.2, position: [0, 0, 0], organ: kidney}\n",
                   "t.yaml:8: field 'objects[0].radius'", "<= 0.05"));
  CHECK(fails_with(HEAD "objects:\n  - {name: s, kind: cube, radius: 0.01, position: [0, 0, 0], organ: kidney}\n",
                   "field 'objects[0].kind'", "must be one of: stone"));
  CHECK(fails_with(HEAD "objects:\n  - {name: s, radius: 0.004, position: [0, 0, 0], organ: kidney}\n"
                        "  - {name: s, radius: 0.004, position: [0, 0, 0], organ: kidney}\n",
                   "t.yaml:9: field 'objects[1].name'", "duplicate object name 's'"));
  CHECK(fails_with(HEAD "objects:\n  - {name: s, radius: 0.004, position: [0, 0], organ: kidney}\n",
                   "field 'objects[0].position'", "list of 3 numbers"));
  CHECK(fails_with(HEAD "objects:\n  - {name: s, radius: 0.004, position: [0, 0, 0], organ: kidney, mass: 1}\n",
                   "field 'objects[0].mass'", "unknown key"));
}

static void test_task_errors(void) {
  CHECK(fails_with(HEAD TOOLS "tasks:\n  - {name: t, kind: stone_removal, tool: g, object: s}\n",
                   "t.yaml:12: field 'tasks[0].tool'", "needs an extractor (tool 'g' is a grasper)"));
  CHECK(fails_with(HEAD TOOLS "tasks:\n  - {name: t, kind: stone_removal, tool: x, object: s}\n",
                   "t.yaml:12: field 'tasks[0].object'", "no object named 's' (known: none)"));
  CHECK(fails_with(HEAD TOOLS "tasks:\n  - {name: t, kind: stone_removal, tool: x}\n", "field 'tasks[0].object'",
                   "required field missing"));
  CHECK(fails_with(HEAD TOOLS "tasks:\n  - {name: t, kind: grasp_pull, tool: p}\n", "field 'tasks[0].tool'",
                   "needs a grasper (tool 'p' is a probe)"));
  CHECK(fails_with(HEAD TOOLS "tasks:\n  - {name: t, kind: palpate_target, tool: x, target: [0, 0, 0]}\n",
                   "field 'tasks[0].tool'", "is an extractor"));
  CHECK(fails_with(HEAD TOOLS "tasks:\n  - {name: t, kind: palpate_target, tool: p}\n", "field 'tasks[0].target'",
                   "required field missing"));
  CHECK(fails_with(HEAD TOOLS "tasks:\n  - {name: t, kind: grasp_pull, tool: g, target: [0, 0, 0]}\n",
                   "t.yaml:12: field 'tasks[0].target'", "a grasp_pull task does not use this key"));
  CHECK(fails_with(HEAD TOOLS "tasks:\n  - {name: t, kind: grasp_pull, tool: nobody}\n", "field 'tasks[0].tool'",
                   "no tool named 'nobody' (known: p, g, x)"));
  CHECK(fails_with(HEAD TOOLS "tasks:\n  - {name: t, kind: dance, tool: p}\n", "field 'tasks[0].kind'",
                   "must be one of: stone_removal, palpate_target, grasp_pull"));
  CHECK(fails_with(HEAD TOOLS "tasks:\n  - {name: t, tool: p}\n", "field 'tasks[0].kind'", "required field missing"));
  CHECK(fails_with(HEAD TOOLS "tasks:\n  - {name: t, kind: grasp_pull, tool: g, distance: 0}\n",
                   "field 'tasks[0].distance'", "must be > 0"));
  CHECK(fails_with(HEAD TOOLS
                   "tasks:\n  - {name: t, kind: grasp_pull, tool: g}\n  - {name: t, kind: grasp_pull, tool: g}\n",
                   "t.yaml:13: field 'tasks[1].name'", "duplicate task name 't'"));
}

int main(void) {
  test_full();
  test_defaults();
  test_tool_errors();
  test_object_errors();
  test_task_errors();
  return check_report("test_scene_tools");
}
