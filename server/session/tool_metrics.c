/* SPDX-License-Identifier: Apache-2.0 */
#include "session/tool_metrics.h"

#include <stdio.h>
#include <string.h>

void tool_tally_update(tool_tally_t *tl, const tool_rt_t *tool, double dt) {
  int holding = tool->active && (tool->grasp.active || tool->stone >= 0);
  if (holding && !tl->was_holding) tl->grasps++;
  if (holding) tl->grasp_time += dt;
  tl->was_holding = holding;
}

double tool_exploration_time(const runtime_t *rt, size_t t) {
  for (size_t i = 0; i < rt->ntasks; i++) {
    const task_rt_t *k = &rt->tasks[i];
    if (k->cfg->tool == (int)t && k->completed && !strcmp(k->cfg->kind, "palpate_target")) return k->t_end - k->t_start;
  }
  return -1;
}

void tool_metrics_fill(viscera_ToolMetrics *m, const runtime_t *rt, size_t t, const thr_tracker_t *thr,
                       const tool_tally_t *tl, uint64_t sim_time_ns) {
  memset(m, 0, sizeof *m);
  m->tool_id = (uint32_t)t;
  m->sim_time_ns = sim_time_ns;
  snprintf(m->name, sizeof m->name, "%s", rt->tools[t].cfg->name);
  /* The runtime's peak includes grasp pulls and tool-tool contact; the
   * tracker's is the same force sampled once per step. */
  m->peak_force = rt->tools[t].peak_force > thr->peak_force ? rt->tools[t].peak_force : thr->peak_force;
  m->time_above_st = thr->time_above[THR_ST];
  m->time_above_mpf = thr->time_above[THR_MPF];
  m->time_above_sft = thr->time_above[THR_SFT];
  m->contact_time = thr->contact_time;
  m->mean_contact_force = thr_mean_contact_force(thr);
  m->path_length = thr->path_length;
  m->exploration_time = tool_exploration_time(rt, t);
  m->grasps = tl->grasps;
  m->grasp_time = tl->grasp_time;
  for (size_t i = 0; i < rt->ntasks; i++) {
    const task_rt_t *k = &rt->tasks[i];
    if (k->cfg->tool != (int)t) continue;
    m->tasks_total++;
    if (k->completed) {
      m->tasks_completed++;
      m->operation_time += k->t_end - k->t_start;
    }
  }
}
