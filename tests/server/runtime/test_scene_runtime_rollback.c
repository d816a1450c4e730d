/* SPDX-License-Identifier: Apache-2.0 */
/* test_scene_runtime_rollback: an organ whose state the guard restores but
 * that can never step (here a node velocity of 1e308: every step overflows
 * and rolls back to it) is put back to rest after RUNTIME_ROLLBACK_RESET
 * consecutive rolled-back steps, and steps again (issue 15: a seat rolled
 * back 13,441 times in 29 s and `reset` did not help). Every model family
 * goes through the same guard: the surface mass-spring kidney and the
 * xpbd spleen (embedded surface) are both checked. */
#include <string.h>

#include "check.h"
#include "test_runtime.h"

static runtime_t rt;
static scene_t sc;

static void check_model(const char *mesh, const char *keys) {
  CHECK(test_runtime_one_organ(&rt, &sc, "rollback", mesh, keys, "radius: 0.003, stiffness: 400", NULL));
  if (!rt.norgans) return;
  for (int i = 0; i < 5; i++) CHECK(runtime_step(&rt) == 0);
  model_t *m = rt.organs[0].model;
  m->v[0] = 1e308; /* finite, so the guard saves it; any step from it overflows */
  m->v[4] = -1e308;
  model_note_outside_write(m);
  int rolled = 0, reset_at = -1;
  for (int i = 0; i < RUNTIME_ROLLBACK_RESET + 50; i++) {
    int r = runtime_step(&rt);
    if (rt.organs_reset & 1u) {
      CHECK(reset_at < 0);
      reset_at = i;
      /* At rest: every node at its rest position, no velocity. */
      int at_rest = 1;
      for (size_t k = 0; k < 3 * m->nnodes; k++)
        if (m->x[k] != m->x_rest[k] || m->v[k] != 0) at_rest = 0;
      CHECK(at_rest);
    }
    if (reset_at < 0 || i == reset_at)
      rolled += r;
    else
      CHECK(r == 0); /* steps again */
  }
  printf("%s: %d rolled-back steps, reset at step %d\n", mesh, rolled, reset_at);
  CHECK(rolled == RUNTIME_ROLLBACK_RESET);
  CHECK(reset_at == RUNTIME_ROLLBACK_RESET - 1);
  CHECK(rt.organs[0].rest_resets == 1);
  CHECK(rt.organs[0].rollback_run == 0);
  runtime_destroy(&rt);
}

int main(void) {
  check_model("kidney.obj", "");
  check_model("spleen.obj", "    model: xpbd\n");
  return check_report("test_scene_runtime_rollback");
}
