/* SPDX-License-Identifier: Apache-2.0 */
#include "session/scene_check.h"

#include <math.h>

#include "vtime.h"

int scene_check_cost(runtime_t *rt, FILE *out, FILE *warn) {
  const double dt = rt->scene.dt;
  double total = 0, worst = -1;
  size_t worst_i = 0;
  for (size_t i = 0; i < rt->norgans; i++) {
    model_t *m = rt->organs[i].model;
    uint64_t t0 = vtime_thread_cpu_ns();
    for (int k = 0; k < SCENE_CHECK_STEPS; k++) m->ops->step(m, dt);
    double per_step = (double)(vtime_thread_cpu_ns() - t0) * 1e-9 / SCENE_CHECK_STEPS;
    fprintf(out, "  organ '%s': %.3g ms CPU per step (%d steps timed)\n", rt->organs[i].cfg->name, per_step * 1e3,
            SCENE_CHECK_STEPS);
    total += per_step;
    if (per_step > worst) worst = per_step, worst_i = i;
  }
  fprintf(out, "step cost: %.3g ms CPU for a %.3g ms step (%.0f %% of dt, one core)\n", total * 1e3, dt * 1e3,
          100.0 * total / dt);
  if (rt->norgans == 0 || total <= SCENE_CHECK_MARGIN * dt) return 0;
  const organ_rt_t *o = &rt->organs[worst_i];
  if (total > dt)
    fprintf(warn,
            "viscera-server: warning: this scene will not keep real time at dt %.3g ms: a step costs %.3g ms of CPU "
            "(about %.0f %% of real time); organ '%s' costs most (%.3g ms: model %s, %zu nodes, %d sub-step(s)): "
            "a coarser mesh, a softer material or tool (fewer sub-steps) or a larger dt would help\n",
            dt * 1e3, total * 1e3, 100.0 * dt / total, o->cfg->name, worst * 1e3, o->model->ops->name, o->model->nnodes,
            o->model->substeps);
  else
    fprintf(warn,
            "viscera-server: warning: little margin: a step costs %.3g ms of CPU of its %.3g ms (%.0f %%) before "
            "contact and cutting; organ '%s' costs most (%.3g ms)\n",
            total * 1e3, dt * 1e3, 100.0 * total / dt, o->cfg->name, worst * 1e3);
  return 1;
}

int scene_check_sizes(const runtime_t *rt, FILE *warn) {
  int n = 0;
  for (size_t i = 0; i < rt->norgans; i++) {
    const model_t *m = rt->organs[i].model;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t v = 0; v < m->nsurf; v++)
      for (int k = 0; k < 3; k++) {
        lo[k] = fmin(lo[k], m->surf_rest[3 * v + k]);
        hi[k] = fmax(hi[k], m->surf_rest[3 * v + k]);
      }
    double side = 0;
    for (int k = 0; k < 3; k++) side = fmax(side, hi[k] - lo[k]);
    if (m->nsurf == 0 || (side >= SCENE_CHECK_MIN_SIZE_M && side <= SCENE_CHECK_MAX_SIZE_M)) continue;
    fprintf(warn,
            "viscera-server: warning: organ '%s' is %.4g m across (%.4g x %.4g x %.4g m), outside the plausible "
            "%.3g..%.3g m for an organ: scene files are in metres; a mesh in millimetres needs scale: 0.001 "
            "(or viscera-asset convert --scale 0.001)\n",
            rt->organs[i].cfg->name, side, hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], SCENE_CHECK_MIN_SIZE_M,
            SCENE_CHECK_MAX_SIZE_M);
    n++;
  }
  return n;
}
