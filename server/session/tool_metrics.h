/* SPDX-License-Identifier: Apache-2.0 */
/* tool_metrics: the per-tool trainee measures published on ToolMetrics and
 * printed at exit (issue 4): the palpation measures of thresholds.h for
 * this tool alone, grasps, time holding, exploration time to the target
 * and operation time of the tool's tasks. */
#ifndef VISCERA_TOOL_METRICS_H
#define VISCERA_TOOL_METRICS_H

#include <stdint.h>

#include "runtime/scene_runtime.h"
#include "training/thresholds.h"
#include "viscera.h"

typedef struct tool_tally {
  uint32_t grasps;   /* grasps begun (tissue or stone) */
  double grasp_time; /* s holding */
  int was_holding;
} tool_tally_t;

/* Once per step of dt seconds. */
void tool_tally_update(tool_tally_t *tl, const tool_rt_t *tool, double dt);

/* Exploration time to the target: the operation time of the tool's first
 * completed palpate_target task, -1 when none is completed. */
double tool_exploration_time(const runtime_t *rt, size_t t);

void tool_metrics_fill(viscera_ToolMetrics *m, const runtime_t *rt, size_t t, const thr_tracker_t *thr,
                       const tool_tally_t *tl, uint64_t sim_time_ns);

#endif
