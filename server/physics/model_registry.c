/* SPDX-License-Identifier: Apache-2.0 */
/* model_registry: model_create() picks the implementation of the scene's
 * model name from one table.
 *
 * Adding a model: write `model_t *model_NAME_create(const model_params_t *p,
 * verr_t *err)` in its own file, add that file to MODEL SOURCES in
 * server/CMakeLists.txt and append ONE line to MODEL_TABLE below:
 *     X("scene_name", model_NAME_create) \
 * The line declares the constructor and registers it. A scene may name a
 * model the parser knows but this build has no entry for: it is refused with
 * "model 'X' is not available in this build".
 *
 * Constructors report what is wrong without naming the organ: model_create
 * prefixes "organ 'NAME': " to every message, as model.h promises. */
#include <stdio.h>
#include <string.h>

#include "physics/model.h"

/* clang-format off */
#define MODEL_TABLE(X)                                      \
  X("mass_spring_surface", model_mass_spring_surface_create) \
  X("mass_spring_tet", model_mass_spring_tet_create)         \
  X("molecular", model_molecular_create)                     \
  X("pbd", model_pbd_create)                                 \
  X("xpbd", model_pbd_create)                                \
  X("vertex_based", model_vertex_based_create)               \
  X("adaptive_mass_spring", model_adaptive_create)           \
  /* append one line per model above this comment */
/* clang-format on */

typedef model_t *(*model_ctor_t)(const model_params_t *p, verr_t *err);

#define DECLARE_CTOR(name, fn) model_t *fn(const model_params_t *p, verr_t *err);
MODEL_TABLE(DECLARE_CTOR)
#undef DECLARE_CTOR

static const struct {
  const char *name;
  model_ctor_t create;
} MODELS[] = {
#define ENTRY(name, fn) {name, fn},
    MODEL_TABLE(ENTRY)
#undef ENTRY
};

model_t *model_create(const model_params_t *p, verr_t *err) {
  const scene_organ_t *cfg = p->cfg;
  for (size_t i = 0; i < sizeof MODELS / sizeof MODELS[0]; i++) {
    if (strcmp(cfg->model, MODELS[i].name) != 0) continue;
    verr_t e;
    memset(&e, 0, sizeof e);
    model_t *m = MODELS[i].create(p, &e);
    if (!m) {
      if (!e.msg[0]) snprintf(e.msg, sizeof e.msg, "model '%s' could not be built", cfg->model);
      verr_set(err, "organ '%s': %s", cfg->name, e.msg);
    }
    return m;
  }
  verr_set(err, "organ '%s': model '%s' is not available in this build", cfg->name, cfg->model);
  return NULL;
}
