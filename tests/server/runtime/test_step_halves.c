/* SPDX-License-Identifier: Apache-2.0 */
/* test_step_halves: runtime_step in two halves (scene_runtime.h, issue 17
 * item 5: the session answers a fresh command before the tissue step).
 * - Two runtimes on the same kidney scene driven by the same probe path
 *   (down onto the kidney, a press of several mm, a hold): one steps with
 *   runtime_step, the other with runtime_step_begin, then
 *   runtime_feedback_preview, then runtime_step_finish. After every step
 *   the surfaces, the tool records (force, peak, proxy, feedback fields,
 *   contributions) and the event queues are identical bit for bit: the
 *   preview changes nothing of the step.
 * - The preview is the feedback against the current surface: it is in
 *   contact exactly when the god-object is after the contact phase, its
 *   force is K (proxy - tip) clamped (the proxy spring, no shaft here), it
 *   carries the step's new tip, and once the hold is steady it agrees with
 *   the force after the tissue step within 2 %. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "runtime/scene_runtime.h"
#include "test_runtime.h"

#define KIDNEY                                                                                                         \
  "scene: t\nphysics: {dt: 0.001}\n"                                                                                   \
  "organs:\n  - {name: kidney, mesh: ../meshes/kidney.obj, material: {mass: 0.15, stiffness: 30, damping: 0.02, "      \
  "home_stiffness: 30, home_damping: 0.005}}\n"                                                                        \
  "tools:\n  - {name: probe, radius: 0.003, stiffness: 400, max_force: 4}\n"

static runtime_t rt_a, rt_b; /* large */
static scene_t sc_a, sc_b;
static tool_rt_t preview[SCENE_MAX_TOOLS];
static verr_t e;

static int same_state(void) {
  const model_t *a = rt_a.organs[0].model, *b = rt_b.organs[0].model;
  int same = a->nsurf == b->nsurf && !memcmp(a->surf_x, b->surf_x, 3 * a->nsurf * sizeof(double)) &&
             !memcmp(a->v, b->v, 3 * a->nnodes * sizeof(double));
  const tool_rt_t *ta = &rt_a.tools[0], *tb = &rt_b.tools[0];
  same = same && !memcmp(ta->force, tb->force, sizeof ta->force) && ta->peak_force == tb->peak_force &&
         !memcmp(&ta->proxy, &tb->proxy, sizeof ta->proxy) && !memcmp(&ta->from, &tb->from, sizeof ta->from) &&
         !memcmp(ta->fb_pos, tb->fb_pos, sizeof ta->fb_pos) &&
         !memcmp(ta->fb_normal, tb->fb_normal, sizeof ta->fb_normal) && ta->fb_contact == tb->fb_contact &&
         ta->npatch == tb->npatch;
  same = same && rt_a.events.n == rt_b.events.n && rt_a.steps == rt_b.steps && rt_a.sim_time == rt_b.sim_time;
  return same;
}

int main(void) {
  if (!test_runtime_load(&rt_a, &sc_a, KIDNEY, &e) || !test_runtime_load(&rt_b, &sc_b, KIDNEY, &e)) {
    CHECK(0);
    return check_report("test_step_halves");
  }
  int identical = 1, contact_steps = 0, spring_steps = 0, preview_agree = 1, spring_ok = 1, held = 0;
  double worst_rel = 0, max_f = 0;
  for (int i = 0; i < 900; i++) {
    /* From 8 mm above the press point down 12 mm in 0.6 s, then held. */
    double z = i < 600 ? 0.035 - 0.012 * i / 600.0 : 0.023, p[3] = {0.012, 0.004, z};
    runtime_set_tool(&rt_a, 0, p, 4);
    runtime_set_tool(&rt_b, 0, p, 4);
    double start = rt_b.sim_time;
    runtime_step(&rt_a);
    runtime_step_begin(&rt_b);
    runtime_feedback_preview(&rt_b, preview);
    const tool_rt_t *pv = &preview[0], *tb = &rt_b.tools[0];
    /* The preview reads the step's new tip and the god-object as the
     * contact phase left it; time has not moved. */
    preview_agree &=
        !memcmp(pv->cmd.pos, p, sizeof pv->cmd.pos) && pv->fb_contact == tb->proxy.in_contact && rt_b.sim_time == start;
    if (pv->fb_contact) {
      contact_steps++;
    }
    if (pv->fb_contact && !pv->from.shaft_hits) {
      spring_steps++;
      double f[3];
      for (int k = 0; k < 3; k++) f[k] = 400 * (pv->fb_pos[k] - p[k]);
      double mag = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]), scale = mag > 4 ? 4 / mag : 1;
      for (int k = 0; k < 3; k++) spring_ok &= fabs(pv->force[k] - f[k] * scale) < 1e-9;
    }
    double before[3];
    memcpy(before, pv->force, sizeof before);
    runtime_step_finish(&rt_b);
    identical &= same_state();
    rt_a.events.n = rt_b.events.n = 0;
    double fa = sqrt(tb->force[0] * tb->force[0] + tb->force[1] * tb->force[1] + tb->force[2] * tb->force[2]);
    max_f = fmax(max_f, fa);
    if (i >= 850) { /* steady hold: the tissue barely moves within a step */
      double d = sqrt((before[0] - tb->force[0]) * (before[0] - tb->force[0]) +
                      (before[1] - tb->force[1]) * (before[1] - tb->force[1]) +
                      (before[2] - tb->force[2]) * (before[2] - tb->force[2]));
      worst_rel = fmax(worst_rel, d / fmax(fa, 1e-9));
      held++;
    }
  }
  printf("contact steps %d (%d without the shaft), peak force %.3f N, preview vs after-step at the hold: worst %.4f "
         "relative\n",
         contact_steps, spring_steps, max_f, worst_rel);
  CHECK(identical);
  CHECK(preview_agree);
  CHECK(spring_ok && spring_steps > 100);
  CHECK(contact_steps > 300); /* the press was real */
  CHECK(max_f > 0.5);
  CHECK(held == 50 && worst_rel < 0.02);
  return check_report("test_step_halves");
}
