/* SPDX-License-Identifier: Apache-2.0 */
/* docs/numerics.md §5 case 14: NaN (or Inf) injected into one vertex is
 * detected within one step, the step rolls back and reports, and nothing
 * spreads.
 *
 * For the surface and the tetrahedral mass-spring model and every
 * integrator, three injections:
 *  - a NaN force on one surface vertex from the contact hook, in the second
 *    sub-step of a step (a corrupt contact);
 *  - a NaN written into one node's position between steps;
 *  - an Inf written into one node's velocity between steps.
 * Each time the very step returns -1, the rollback counter goes up by one,
 * and every node and surface vertex is finite and back where it was before
 * the step; for a write between steps, where "before the step" is the
 * corrupt state, back where it was before the previous step (the last state
 * the model saw finite). The next clean step returns 0. Then a two-organ scene through the runtime: NaN in one organ
 * rolls that organ back, reports one rolled-back organ, and the other organ steps on. */
#include <stdint.h>

#include "runtime/scene_runtime.h"
#include "stab_util.h"
#include "test_runtime.h"

static const char *const INTEGRATORS[] = {"explicit_euler", "symplectic_euler", "verlet", "rk4",
                                          "implicit_euler", "implicit_pcg"};

typedef struct bad_hook {
  int calls, poison_at; /* poison the call with this index (0-based), -1: never */
} bad_hook_t;

static void poison(model_t *m, void *ctx) {
  bad_hook_t *b = ctx;
  if (b->calls++ == b->poison_at) {
    const double f[3] = {NAN, 0, 0};
    m->ops->add_surface_force(m, 3, f);
  }
}

static int same(const double *a, const double *b, size_t n) { return memcmp(a, b, n * sizeof(double)) == 0; }

/* The step must fail, count, and leave x, v, surf_x equal to the given copies. */
static int rolled_back_to(model_t *m, uint64_t rollbacks, const double *x, const double *v, const double *sx) {
  return m->rollbacks == rollbacks && same(m->x, x, 3 * m->nnodes) && same(m->v, v, 3 * m->nnodes) &&
         same(m->surf_x, sx, 3 * m->nsurf) && stab_finite(m->x, 3 * m->nnodes) && stab_finite(m->v, 3 * m->nnodes) &&
         stab_finite(m->surf_x, 3 * m->nsurf);
}

static void one_model(const mesh_t *mesh, const char *model, const char *integrator) {
  char extra[400];
  snprintf(extra, sizeof extra,
           "    model: %s\n    integrator: %s\n    solver: {substeps: 3, tet_size: 0.01}\n"
           "    material: {mass: 0.05, stiffness: 20, damping: 0.05, home_stiffness: 10, home_damping: 0.01}\n",
           model, integrator);
  scene_organ_t c = stab_organ(extra);
  verr_t err;
  model_t *m = stab_model(&c, mesh, NULL, 1e-3, &err);
  CHECK(m != NULL);
  if (!m) {
    fprintf(stderr, "%s\n", err.msg);
    return;
  }
  size_t n3 = 3 * m->nnodes, s3 = 3 * m->nsurf;
  double *x = malloc(n3 * sizeof(double)), *v = malloc(n3 * sizeof(double)), *sx = malloc(s3 * sizeof(double));
  bad_hook_t hook = {.poison_at = -1};
  m->hook = poison;
  m->hook_ctx = &hook;
  /* Get it moving first, so "as before" is not simply the rest state. */
  for (size_t i = 0; i < n3; i++) m->x[i] += 1e-3 * stab_rand();
  model_note_outside_write(m);
  for (int s = 0; s < 5; s++) CHECK(m->ops->step(m, 1e-3) == 0);

  /* NaN force in the second sub-step. */
  memcpy(x, m->x, n3 * sizeof(double));
  memcpy(v, m->v, n3 * sizeof(double));
  memcpy(sx, m->surf_x, s3 * sizeof(double));
  hook.calls = 0;
  hook.poison_at = 1;
  int rc = m->ops->step(m, 1e-3);
  CHECK(rc == -1 && hook.calls >= 2);
  CHECK(rolled_back_to(m, 1, x, v, sx));
  hook.poison_at = -1;

  /* NaN position written between steps: back to the last finite state. */
  memcpy(x, m->x, n3 * sizeof(double));
  memcpy(v, m->v, n3 * sizeof(double));
  memcpy(sx, m->surf_x, s3 * sizeof(double));
  CHECK(m->ops->step(m, 1e-3) == 0 && stab_finite(m->x, n3));
  m->x[3 * (m->nnodes / 2) + 1] = NAN;
  model_note_outside_write(m);
  CHECK(m->ops->step(m, 1e-3) == -1);
  CHECK(rolled_back_to(m, 2, x, v, sx));

  /* Inf velocity between steps. */
  memcpy(x, m->x, n3 * sizeof(double));
  memcpy(v, m->v, n3 * sizeof(double));
  memcpy(sx, m->surf_x, s3 * sizeof(double));
  CHECK(m->ops->step(m, 1e-3) == 0);
  m->v[0] = INFINITY;
  model_note_outside_write(m);
  CHECK(m->ops->step(m, 1e-3) == -1);
  CHECK(rolled_back_to(m, 3, x, v, sx));
  for (int s = 0; s < 20; s++) CHECK(m->ops->step(m, 1e-3) == 0);
  CHECK(m->rollbacks == 3 && stab_finite(m->x, n3) && stab_finite(m->surf_x, s3));
  free(x);
  free(v);
  free(sx);
  model_destroy(m);
}

/* Two organs from the generated spleen through the runtime: one surface,
 * one tetrahedral, side by side. */
static void runtime_case(void) {
  const char *src = getenv("VISCERA_SOURCE_DIR");
  CHECK(src != NULL); /* set by ctest */
  if (!src) return;
  static scene_t sc;
  static runtime_t rt;
  if (!test_runtime_load(&rt, &sc,
                         "scene: nan\norgans:\n"
                         "  - {name: a, mesh: ../meshes/spleen.obj}\n"
                         "  - {name: b, mesh: ../meshes/spleen.obj, model: mass_spring_tet, position: [0.2, 0, 0]}\n",
                         NULL)) {
    CHECK(!"two-organ scene loads");
    return;
  }
  for (int s = 0; s < 10; s++) CHECK(runtime_step(&rt) == 0);
  for (size_t o = 0; o < 2; o++) {
    model_t *m = rt.organs[o].model, *other = rt.organs[1 - o].model;
    size_t n3 = 3 * m->nnodes;
    double *x = malloc(n3 * sizeof(double));
    memcpy(x, m->x, n3 * sizeof(double));
    CHECK(runtime_step(&rt) == 0);
    other->x[0] += 1e-3; /* the other organ moves in this step */
    model_note_outside_write(other);
    double other_before = other->x[0];
    uint64_t other_rollbacks = other->rollbacks;
    m->x[5] = NAN;
    model_note_outside_write(m);
    CHECK(runtime_step(&rt) == 1);
    CHECK(m->rollbacks == 1 && same(m->x, x, n3));
    CHECK(other->rollbacks == other_rollbacks && other->x[0] != other_before &&
          stab_finite(other->x, 3 * other->nnodes));
    CHECK(runtime_step(&rt) == 0);
    free(x);
  }
  runtime_destroy(&rt);
}

int main(void) {
  mesh_t box;
  stab_box(&box, 3, 3, 3, 0.03, 0.03, 0.03);
  for (size_t k = 0; k < sizeof INTEGRATORS / sizeof INTEGRATORS[0]; k++) {
    one_model(&box, "mass_spring_surface", INTEGRATORS[k]);
    one_model(&box, "mass_spring_tet", INTEGRATORS[k]);
  }
  mesh_free(&box);
  runtime_case();
  printf("NaN/Inf injection: 2 models x 5 integrators x 3 injections rolled back in the same step; runtime: one "
         "organ rolled back, the other stepped on\n");
  return check_report("stab_nan");
}
