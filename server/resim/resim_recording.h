/* SPDX-License-Identifier: Apache-2.0 */
/* resim_recording: what viscera-resim needs from a session recording
 * (recording.h), decoded into plain arrays: the SceneInfo, every tool's
 * ToolCommands, ContactFeedbacks and releases (CLIENT_LOST events) in the
 * form resim_schedule.h takes, and every organ's MeshState keyframes and
 * MeshDelta frames with their server step.
 *
 * Steps are round(sim_time_ns / dt_ns) with dt from the recorded SceneInfo.
 * The file is untrusted: samples that do not decode, name an organ or tool
 * the SceneInfo does not have, or carry a keyframe of the wrong size are
 * skipped and counted (`skipped`, with the first reason in `first_skip`),
 * never indexed; so are samples beyond RESIM_MAX_SIM_S. Only data rows (kind 0) are read. */
#ifndef VISCERA_RESIM_RECORDING_H
#define VISCERA_RESIM_RECORDING_H

#include <stddef.h>
#include <stdint.h>

#include "resim/resim_schedule.h"
#include "runtime/tool_command.h"
#include "scene.h"
#include "verr.h"

/* Samples stamped later than this (s of simulated time) are skipped: a
 * garbled time must not size the schedule. */
#define RESIM_MAX_SIM_S 21600.0
/* ... and so are samples whose sim time lies more than this (s) beyond the
 * wall time the server had run when it wrote them (resim_recording.c
 * step_of: the recording's own span bounds the schedule). */
#define RESIM_SPAN_SLACK_S 10.0
/* A keyframe with more vertices than this is skipped (a garbled length must
 * not size an allocation). */
#define RESIM_MAX_VERTS (1u << 22)

typedef struct resim_organ_info {
  char name[65];
  uint32_t nverts, ntris;
} resim_organ_info_t;

typedef struct resim_keyframe {
  uint32_t organ, keyframe_seq, topology_version;
  uint64_t step;
  uint32_t nverts, ntris; /* of this keyframe (a topology change changes them) */
  float *pos;             /* 3 nverts */
  uint32_t *tris;         /* 3 ntris */
  int done;               /* compared (resim_run) */
} resim_keyframe_t;

typedef struct resim_delta {
  uint32_t organ, keyframe_seq, topology_version, frame_seq;
  uint64_t step;
  float quant;
  uint32_t count;
  uint32_t *idx;
  int16_t *dq;
  size_t dq_len;
  int done; /* compared (resim_run) */
} resim_delta_t;

/* What the server applied (idl AppliedInput, issue 16), one entry per tool
 * command, release or SessionControl, in the server's order. Each entry
 * carries the header of its sample: the runtime's epoch (rebuilds before
 * it) and step, and the loop iteration. */
typedef enum resim_input_kind { RESIM_IN_COMMAND, RESIM_IN_RELEASE, RESIM_IN_CONTROL } resim_input_kind_t;
/* SessionControl kinds, as idl ControlKind numbers them. */
typedef enum resim_control_kind {
  RESIM_CTL_PAUSE,
  RESIM_CTL_RESUME,
  RESIM_CTL_SET_THRESHOLDS,
  RESIM_CTL_RESET,
  RESIM_CTL_SET_MATERIAL,
  RESIM_CTL_ASSIGN_TOOL,
  RESIM_CTL_GUIDE,
  RESIM_CTL_START_TASK
} resim_control_kind_t;

typedef struct resim_input {
  uint64_t tick, step;
  uint32_t epoch;
  resim_input_kind_t kind;
  uint32_t tool;    /* COMMAND, RELEASE */
  tool_input_t cmd; /* COMMAND: exactly what the tool took */
  /* CONTROL: */
  int control; /* resim_control_kind_t */
  int ctl_tool, ctl_organ;
  double values[4];
  int result; /* 0 applied, 1 rebuilt, 2 rebuild refused (old scene rebuilt), -1 refused */
  int task;   /* START_TASK: the task started, else -1 */
} resim_input_t;

/* Interaction events (idl SessionEvent GRASP_*, TASK_*, CUT_*), as the
 * runtime reports them (interaction/events.h kinds). */
typedef struct resim_event {
  int kind; /* iev_kind_t */
  int tool, organ;
  double value;
  uint64_t step;
} resim_event_t;

/* A recorded ObjectState; epoch counted from its simulated time going back
 * (a rebuild restarts it). */
typedef struct resim_object {
  uint32_t object, epoch;
  uint64_t step;
  float pos[3];
  int held_by, removed;
  int done;
} resim_object_t;

/* A recorded ToolMetrics. */
typedef struct resim_tool_metrics {
  uint32_t tool, epoch;
  uint64_t step;
  double peak_force, time_above[3], contact_time, path_length, grasp_time, operation_time;
  uint32_t grasps, tasks_completed;
  int done;
} resim_tool_metrics_t;

/* SceneSource (issue 16): the scene text and the build that ran it. */
typedef struct resim_source {
  int have;
  char path[1025];
  char *text; /* owned */
  char text_sha256[65];
  size_t nmeshes;
  struct {
    char path[1025], sha256[65];
    uint64_t size;
  } meshes[SCENE_MAX_ORGANS];
  char version[65], compiler[129], build_flags[257], station[65];
  /* A resumed session (SceneSource.resume_state): the state it started
   * from (owned; NULL/0 from rest) and its checkpoint file's digest. */
  unsigned char *resume;
  size_t resume_len;
  char resume_sha256[65];
  /* Set by resim_resume (resim_run.h): restored, at which step, and where
   * each tool's measures are in `resume` (training/measures_blob.h). */
  int resumed;
  uint64_t resumed_step;
  size_t tool_at[SCENE_MAX_TOOLS];
} resim_source_t;

typedef struct resim_recording {
  /* SceneInfo (the last one recorded). */
  int have_scene;
  char scene[65];
  double dt, publish_hz;
  float quant_step;
  size_t norgans, ntools;
  resim_organ_info_t organs[SCENE_MAX_ORGANS];
  /* Per tool (index = tool_id < ntools). */
  resim_tool_input_t tools[SCENE_MAX_TOOLS];
  /* Per organ, sorted by step. */
  resim_keyframe_t *keys;
  size_t nkeys;
  resim_delta_t *deltas;
  size_t ndeltas;
  uint64_t last_step; /* the latest frame (keyframe or delta) recorded */
  /* Applied inputs (empty in a recording made before issue 16: the
   * schedule is then rebuilt from ToolCommand and ContactFeedback). */
  resim_input_t *inputs;
  size_t ninputs;
  uint64_t applied_lost; /* AppliedInput samples missing (seq gaps; format-1 samples carry no seq) */
  resim_event_t *events; /* recorded interaction events, in recording order */
  size_t nevents;
  resim_object_t *objects;
  size_t nobjects;
  resim_tool_metrics_t *metrics;
  size_t nmetrics;
  resim_source_t source;
  /* Samples read per topic and skipped. */
  uint64_t n_commands, n_feedback, n_events, n_states, n_deltas, n_applied, n_objects, n_metrics;
  uint64_t skipped;
  char first_skip[256];
  char warnings[512];  /* from the recording reader (damage, missing pragmas) */
  char partition[256]; /* the session read (resim_session.h), "" when the recording holds only one */
  size_t nruns, run;   /* the session's server runs and the one read (resim_session.h; run 0: the only one) */
} resim_recording_t;

/* Reads the session of `partition` (NULL: the recording's only one; a
 * lab's recording of several seats needs one, resim_session.h), and of it
 * server run `run` (1 = the first, 0 = the last: a server restarted while
 * the recorder ran left several).
 * Returns 0, or -1 with err naming the file and what is wrong (not a
 * recording, no SceneInfo, unreadable, several sessions and none chosen,
 * no such run). */
int resim_recording_load(resim_recording_t *rec, const char *path, const char *partition, size_t run, verr_t *err);
void resim_recording_free(resim_recording_t *rec);

#endif
