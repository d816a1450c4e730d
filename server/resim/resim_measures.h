/* SPDX-License-Identifier: Apache-2.0 */
/* resim_measures: the trainee measures the server publishes as ToolMetrics
 * (session/tool_metrics.h), recomputed in a re-simulation so they can be
 * compared with the recorded ones: per tool, the palpation tracker
 * (training/thresholds.h) fed the tool's force, contact and tip after every
 * step, as the server's track_thresholds does, and the grasp tally (grasps
 * begun, time holding), as the server's tool_tally_update does. Levels
 * start from the scene and change with a SET_THRESHOLDS control; a rebuild
 * starts everything again. Plain data, no DDS. */
#ifndef VISCERA_RESIM_MEASURES_H
#define VISCERA_RESIM_MEASURES_H

#include "resim/resim_recording.h"
#include "runtime/scene_runtime.h"
#include "training/thresholds.h"

typedef struct resim_measures {
  thr_tracker_t thr[SCENE_MAX_TOOLS];
  uint32_t grasps[SCENE_MAX_TOOLS];
  double grasp_time[SCENE_MAX_TOOLS];
  int was_holding[SCENE_MAX_TOOLS];
} resim_measures_t;

/* From the scene's levels, nothing accumulated (start, rebuild). */
void resim_measures_init(resim_measures_t *m, const runtime_t *rt);
/* After a step that was not paused. */
void resim_measures_step(resim_measures_t *m, const runtime_t *rt);
/* A SET_THRESHOLDS the server applied: new levels, history kept. */
void resim_measures_levels(resim_measures_t *m, size_t tool, const double v[3]);
/* Tool t's measures as the server's ToolMetrics carries them. */
void resim_measures_fill(const resim_measures_t *m, const runtime_t *rt, size_t t, resim_tool_metrics_t *out);

#endif
