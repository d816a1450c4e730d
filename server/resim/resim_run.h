/* SPDX-License-Identifier: Apache-2.0 */
/* resim_run: re-simulates a recorded session in a fresh runtime and
 * compares, at every recorded frame, the surface with the recorded mesh.
 *
 * resim_check_scene refuses a scene that is not the recorded one (name,
 * dt, quant_step, organ names and vertex/triangle counts, tool count).
 * resim_run rebuilds every tool's command schedule (resim_schedule.h), then
 * steps the runtime from its initial state through the last recorded frame
 * applying, before each step, the scheduled command (or release) exactly as
 * the server did, and at every MeshState keyframe and MeshDelta frame of a
 * step compares the organ's surface with the recording: a keyframe holds
 * float positions, a delta rebuilds the mesh from its keyframe within
 * quant_step / 2 per coordinate (mesh_delta.h). Errors are per coordinate
 * (max) and per vertex (RMS of the distance). A frame is "exact" when
 * encoding the re-simulated surface against the same keyframe reproduces the
 * recorded frame bit for bit (what a bit-deterministic runtime gives). */
#ifndef VISCERA_RESIM_RUN_H
#define VISCERA_RESIM_RUN_H

#include <stdint.h>

#include "resim/resim_recording.h"
#include "resim/resim_schedule.h"
#include "runtime/scene_runtime.h"
#include "verr.h"

typedef struct resim_organ_result {
  uint64_t frames;     /* frames compared (keyframes included) */
  uint64_t keyframes;  /* of which MeshState keyframes */
  uint64_t exact;      /* frames reproduced bit for bit */
  uint64_t unmatched;  /* frames that do not fit the re-simulated surface (another topology) or whose keyframe was
                          not recorded: not compared */
  uint64_t unreached;  /* frames of a topology version, epoch or step the re-simulation never reached */
  double max_err;      /* m, largest per-coordinate difference */
  uint64_t worst_step; /* where */
  double sum_sq;       /* sum over compared vertices of the squared distance */
  uint64_t nsq;        /* vertices in sum_sq */
} resim_organ_result_t;

typedef struct resim_object_result {
  uint64_t compared, exact; /* ObjectState samples compared, reproduced bit for bit (float position, holder, removed) */
  uint64_t mismatched;      /* holder or removed differ, or no such object */
  uint64_t first_mismatch_step;
  uint64_t unreached;
  double max_err; /* m, largest per-coordinate position difference */
  uint64_t worst_step;
} resim_object_result_t;

typedef struct resim_event_result {
  size_t recorded, resim, equal; /* interaction events (grasp, task, cut) */
  char first_difference[320];
} resim_event_result_t;

typedef struct resim_metrics_result {
  uint64_t compared, differ, unreached; /* ToolMetrics samples */
  char first_difference[256];
} resim_metrics_result_t;

typedef struct resim_result {
  uint64_t steps;
  uint64_t rollbacks;
  int applied;                                     /* re-simulated from AppliedInput (else the rebuilt schedule) */
  uint64_t commands, releases, controls, rebuilds; /* applied inputs replayed */
  uint32_t epochs;                                 /* rebuilds the run went through */
  uint64_t resumed_step; /* a resumed session: the step its recorded state starts at; 0 from rest */
  int diverged;          /* the recording asked for a state the run could not reach */
  char divergence[VERR_MSG_LEN];
  resim_organ_result_t organs[SCENE_MAX_ORGANS];
  resim_object_result_t objects;
  resim_event_result_t events;
  resim_metrics_result_t metrics;
  resim_schedule_stats_t sched[SCENE_MAX_TOOLS];
  char first_unmatched[VERR_MSG_LEN + 128];
} resim_result_t;

typedef struct resim_hooks {
  /* Each compared frame (may be NULL). */
  void (*frame)(void *arg, uint64_t step, uint32_t organ, int keyframe, double max_err, double rms, int exact);
  /* About every 1 % of the steps (may be NULL). */
  void (*progress)(void *arg, uint64_t step, uint64_t total);
  void *arg;
} resim_hooks_t;

int resim_check_scene(const runtime_t *rt, const resim_recording_t *rec, verr_t *err);
/* A session resumed from a checkpoint (SceneSource.resume_state): restores
 * its recorded state into `rt` (built from rest from the recording's
 * scene), as the server did, and notes it in rec->source (resumed, the
 * step, where the tools' measures are). Call before checking the scene
 * against the recording and before resim_run. 0 when restored or nothing
 * to restore; -1 with err when the state is refused. */
int resim_resume(runtime_t *rt, resim_recording_t *rec, verr_t *err);

/* rt fresh from runtime_init (and resim_resume); rec from resim_recording_load (its arrays
 * are sorted in place). With applied inputs (idl AppliedInput, issue 16)
 * every recorded tool command, release and SessionControl is re-applied
 * before the step the server took it (pause, rebuilds for RESET and
 * SET_MATERIAL, START_TASK; thresholds and roles do not move the
 * simulation), frames are matched by organ, MeshState topology version (the
 * run counts them as the server's publisher does: +1 per cut or rebuild) and
 * step, ObjectState by epoch and step, and the interaction events (grasp,
 * task, cut) in order. Without them (an older recording) the schedule of
 * resim_schedule.h drives the tool positions only. Returns 0 (a run that
 * could not follow the recording sets res->diverged), or -1 with err when
 * an older recording's schedule cannot be built. */
int resim_run(runtime_t *rt, resim_recording_t *rec, const resim_hooks_t *hooks, resim_result_t *res, verr_t *err);

#endif
