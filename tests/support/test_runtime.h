/* SPDX-License-Identifier: Apache-2.0 */
/* test_runtime: a scene loaded into the real simulation runtime, the
 * fixture of the runtime, interaction, checkpoint and stability tests.
 * Scene texts name their meshes relative to assets/scenes (e.g.
 * "../meshes/kidney.obj") or absolutely; a failure prints the loader's
 * message (file:line, field) on stderr and returns 0, so a test writes
 * CHECK(test_runtime_load(...)). The caller owns the (large, best static)
 * scene and runtime. Implemented in test_runtime.c (viscera_test_support). */
#ifndef VISCERA_TEST_RUNTIME_H
#define VISCERA_TEST_RUNTIME_H

#include "runtime/scene_runtime.h"
#include "scene.h"

/* Loads the YAML text `yaml` (named "t.yaml", based in assets/scenes) into
 * *sc and, when rt is not NULL, *rt: 1, or 0 after printing the error (also
 * left in *err when err is not NULL). */
int test_runtime_load(runtime_t *rt, scene_t *sc, const char *yaml, verr_t *err);

/* The same for the shipped scene assets/scenes/<name> (e.g. "default.yaml"). */
int test_runtime_load_scene(runtime_t *rt, scene_t *sc, const char *name, verr_t *err);

/* One organ from assets/meshes/<mesh> with the organ keys `organ_keys`
 * (YAML lines of the organ entry, each indented four spaces and ending in
 * a newline, or ""), and one probe with the flow-map keys `probe_keys`
 * (e.g. "radius: 0.003, stiffness: 400"): the scene most runtime tests
 * start from, named `scene`. */
int test_runtime_one_organ(runtime_t *rt, scene_t *sc, const char *scene, const char *mesh, const char *organ_keys,
                           const char *probe_keys, verr_t *err);

#endif
