/* SPDX-License-Identifier: Apache-2.0 */
#include "interaction/tasks.h"

#include <string.h>

#include "vmath.h"

void tasks_init(task_rt_t *tasks, const scene_t *scene) {
  for (size_t i = 0; i < scene->ntasks; i++) {
    memset(&tasks[i], 0, sizeof tasks[i]);
    tasks[i].cfg = &scene->tasks[i];
  }
}

static int criterion_met(const task_rt_t *task, const task_tool_view_t *tools, const stone_t *stones) {
  const scene_task_t *c = task->cfg;
  const task_tool_view_t *tool = &tools[c->tool];
  if (!strcmp(c->kind, "stone_removal")) return stones[c->object].removed;
  if (!strcmp(c->kind, "palpate_target"))
    return tool->active && tool->fb_contact && tool->fb_organ >= 0 &&
           v3_dist(tool->fb_pos, c->target) <= c->target_radius;
  /* grasp_pull */
  return tool->active && tool->grasp->active && v3_dist(tool->device, tool->grasp->anchor) >= c->distance;
}

void tasks_update(task_rt_t *tasks, size_t ntasks, const task_tool_view_t *tools, const stone_t *stones,
                  double sim_time, iev_queue_t *q) {
  for (size_t i = 0; i < ntasks; i++) {
    task_rt_t *task = &tasks[i];
    const task_tool_view_t *tool = &tools[task->cfg->tool];
    /* An instructor-started task waits for tasks_start(), whatever the tool does. */
    if (!task->started && !task->cfg->start_instructor && tool->first_cmd_time >= 0) {
      task->started = 1;
      task->t_start = tool->first_cmd_time;
      iev_push(q, (iev_t){.kind = IEV_TASK_STARTED,
                          .tool = task->cfg->tool,
                          .organ = -1,
                          .object = task->cfg->object,
                          .task = (int)i,
                          .value = 0,
                          .sim_time = sim_time});
    }
    if (task->started && !task->completed && criterion_met(task, tools, stones)) {
      task->completed = 1;
      task->t_end = sim_time;
      iev_push(q, (iev_t){.kind = IEV_TASK_COMPLETED,
                          .tool = task->cfg->tool,
                          .organ = -1,
                          .object = task->cfg->object,
                          .task = (int)i,
                          .value = task->t_end - task->t_start,
                          .sim_time = sim_time});
    }
  }
}

void tasks_start(task_rt_t *task, double now) {
  task->started = 1;
  task->completed = 0;
  task->t_start = now;
  task->t_end = 0;
}

double task_operation_time(const task_rt_t *t, double now) {
  if (!t->started) return 0;
  return (t->completed ? t->t_end : now) - t->t_start;
}
