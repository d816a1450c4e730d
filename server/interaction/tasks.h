/* tasks: progress of the scene's training tasks (scene `tasks:`), seed 000
 * Table 2 (operation time per task) and seed 002 ch. 6 (exploration time).
 * A task starts at the first command of its tool (`start: first_command`)
 * or when the instructor starts it (`start: instructor`, SessionControl
 * CONTROL_START_TASK, tasks_start), and completes by its kind's criterion
 * (common/scene.h); operation time = completion - start, in simulated
 * seconds. The runtime evaluates every task once per step. */
#ifndef VISCERA_TASKS_H
#define VISCERA_TASKS_H

#include "events.h"
#include "scene.h"

struct runtime;

typedef struct task_rt {
  const scene_task_t *cfg;
  int started, completed;
  double t_start, t_end; /* s of simulated time */
} task_rt_t;

void tasks_init(task_rt_t *tasks, const scene_t *scene);
/* Starts and completes tasks from the runtime's state after a step,
 * appending IEV_TASK_STARTED / IEV_TASK_COMPLETED to q. */
void tasks_update(task_rt_t *tasks, size_t ntasks, const struct runtime *rt, iev_queue_t *q);
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
