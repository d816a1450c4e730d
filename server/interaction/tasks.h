/* SPDX-License-Identifier: Apache-2.0 */
/* tasks: progress of the scene's training tasks (scene `tasks:`), docs/methods.md A
 * Table 2 (operation time per task) and docs/methods.md B ch. 6 (exploration time).
 * A task starts at the first command of its tool (`start: first_command`)
 * or when the instructor starts it (`start: instructor`, SessionControl
 * CONTROL_START_TASK, tasks_start), and completes by its kind's criterion
 * (common/scene.h); operation time = completion - start, in simulated
 * seconds. The runtime evaluates every task once per step. */
#ifndef VISCERA_TASKS_H
#define VISCERA_TASKS_H

#include "interaction/events.h"
#include "interaction/grasp.h"
#include "interaction/stone.h"
#include "scene.h"

/* What a task's criterion reads of a tool after a step (the runtime's tool
 * record, runtime/tool_rt.h, seen from here). */
typedef struct task_tool_view {
  int active;            /* a valid command has been received */
  double first_cmd_time; /* s of simulated time of the first command, -1 before */
  int fb_contact;        /* anything touches (ContactFeedback) */
  int fb_organ;          /* the organ touched, -1 for stones and tools */
  const double *fb_pos;  /* [3] the tip the hand feels, m */
  const double *device;  /* [3] the commanded tip, m */
  const grasp_t *grasp;  /* what a grasper holds */
} task_tool_view_t;

typedef struct task_rt {
  const scene_task_t *cfg;
  int started, completed;
  double t_start, t_end; /* s of simulated time */
} task_rt_t;

void tasks_init(task_rt_t *tasks, const scene_t *scene);
/* Starts and completes tasks from the state after a step (`tools` indexed
 * by tool, `stones` by object, `sim_time` in s), appending
 * IEV_TASK_STARTED / IEV_TASK_COMPLETED to q. */
void tasks_update(task_rt_t *tasks, size_t ntasks, const task_tool_view_t *tools, const stone_t *stones,
                  double sim_time, iev_queue_t *q);
/* Starts `task` now (s of simulated time), also when it is running or
 * completed: a restart REPLACES the earlier run (completion cleared, clock
 * from now), so ToolMetrics count it once, as not completed until it
 * completes again, with the new run's operation time. The caller reports
 * it (EVENT_TASK_STARTED). */
void tasks_start(task_rt_t *task, double now);
/* Operation time: end - start when completed, time so far when started,
 * 0 before. */
double task_operation_time(const task_rt_t *t, double now);

#endif
