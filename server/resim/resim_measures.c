/* SPDX-License-Identifier: Apache-2.0 */
#include "resim/resim_measures.h"

#include <string.h>

#include "vmath.h"

void resim_measures_init(resim_measures_t *m, const runtime_t *rt) {
  memset(m, 0, sizeof *m);
  for (size_t t = 0; t < rt->ntools; t++) {
    const scene_tool_t *c = rt->tools[t].cfg;
    thr_init(&m->thr[t], c->st, c->mpf, c->sft);
  }
}

void resim_measures_step(resim_measures_t *m, const runtime_t *rt) {
  for (size_t t = 0; t < rt->ntools; t++) {
    const tool_rt_t *tool = &rt->tools[t];
    double f = tool->active ? v3_norm(tool->force) : 0.0;
    int contact = tool->active && tool->fb_contact;
    thr_event_t ev[THR_COUNT];
    thr_update(&m->thr[t], rt->scene.dt, f, contact, tool->active ? tool->cmd.pos : NULL, ev);
    int holding = tool->active && (tool->grasp.active || tool->stone >= 0);
    if (holding && !m->was_holding[t]) m->grasps[t]++;
    if (holding) m->grasp_time[t] += rt->scene.dt;
    m->was_holding[t] = holding;
  }
}

void resim_measures_levels(resim_measures_t *m, size_t tool, const double v[3]) {
  if (tool >= SCENE_MAX_TOOLS) return;
  for (int k = 0; k < THR_COUNT; k++) {
    m->thr[tool].level[k] = v[k];
    m->thr[tool].above[k] = 0;
  }
}

void resim_measures_fill(const resim_measures_t *m, const runtime_t *rt, size_t t, resim_tool_metrics_t *out) {
  const thr_tracker_t *thr = &m->thr[t];
  memset(out, 0, sizeof *out);
  out->tool = (uint32_t)t;
  out->peak_force = rt->tools[t].peak_force > thr->peak_force ? rt->tools[t].peak_force : thr->peak_force;
  for (int k = 0; k < 3; k++) out->time_above[k] = thr->time_above[k];
  out->contact_time = thr->contact_time;
  out->path_length = thr->path_length;
  out->grasps = m->grasps[t];
  out->grasp_time = m->grasp_time[t];
  for (size_t i = 0; i < rt->ntasks; i++) {
    const task_rt_t *k = &rt->tasks[i];
    if (k->cfg->tool != (int)t || !k->completed) continue;
    out->tasks_completed++;
    out->operation_time += k->t_end - k->t_start;
  }
}
