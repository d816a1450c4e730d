/* SPDX-License-Identifier: Apache-2.0 */
/* test_runtime.c: scenes into the runtime for tests (test_runtime.h). */
#include "test_runtime.h"

#include <stdio.h>
#include <string.h>

#include "test_assets.h"

static int finish(int failed, const verr_t *e, verr_t *err) {
  if (err) *err = *e;
  if (failed) {
    fprintf(stderr, "  %s\n", e->msg);
    return 0;
  }
  return 1;
}

int test_runtime_load(runtime_t *rt, scene_t *sc, const char *yaml, verr_t *err) {
  verr_t e;
  memset(&e, 0, sizeof e);
  int failed = scene_load_string(yaml, "t.yaml", test_asset("scenes"), sc, &e) != 0;
  if (!failed && rt) failed = runtime_init(rt, sc, &e) != 0;
  return finish(failed, &e, err);
}

int test_runtime_load_scene(runtime_t *rt, scene_t *sc, const char *name, verr_t *err) {
  char sub[1024];
  snprintf(sub, sizeof sub, "scenes/%s", name);
  verr_t e;
  memset(&e, 0, sizeof e);
  int failed = scene_load(test_asset(sub), sc, &e) != 0;
  if (!failed && rt) failed = runtime_init(rt, sc, &e) != 0;
  return finish(failed, &e, err);
}

int test_runtime_one_organ(runtime_t *rt, scene_t *sc, const char *scene, const char *mesh, const char *organ_keys,
                           const char *probe_keys, verr_t *err) {
  char yaml[4096];
  snprintf(yaml, sizeof yaml, "scene: %s\norgans:\n  - name: organ\n    mesh: ../meshes/%s\n%stools:\n  - {name: probe%s%s}\n",
           scene, mesh, organ_keys ? organ_keys : "", probe_keys && *probe_keys ? ", " : "",
           probe_keys ? probe_keys : "");
  return test_runtime_load(rt, sc, yaml, err);
}
