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
#include "scene.h"
#include "verr.h"

/* Samples stamped later than this (s of simulated time) are skipped: a
 * garbled time must not size the schedule. */
#define RESIM_MAX_SIM_S 21600.0
/* ... and so are samples whose sim time lies more than this (s) beyond the
 * wall time the server had run when it wrote them (resim_recording.c
 * step_of: the recording's own span bounds the schedule). */
#define RESIM_SPAN_SLACK_S 10.0

typedef struct resim_organ_info {
  char name[65];
  uint32_t nverts, ntris;
} resim_organ_info_t;

typedef struct resim_keyframe {
  uint32_t organ, keyframe_seq, topology_version;
  uint64_t step;
  float *pos; /* 3 nverts of the organ */
} resim_keyframe_t;

typedef struct resim_delta {
  uint32_t organ, keyframe_seq, topology_version, frame_seq;
  uint64_t step;
  float quant;
  uint32_t count;
  uint32_t *idx;
  int16_t *dq;
  size_t dq_len;
} resim_delta_t;

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
  /* Samples read per topic and skipped. */
  uint64_t n_commands, n_feedback, n_events, n_states, n_deltas;
  uint64_t skipped;
  char first_skip[256];
  char warnings[512]; /* from the recording reader (damage, missing pragmas) */
} resim_recording_t;

/* Returns 0, or -1 with err naming the file and what is wrong (not a
 * recording, no SceneInfo, unreadable). */
int resim_recording_load(resim_recording_t *rec, const char *path, verr_t *err);
void resim_recording_free(resim_recording_t *rec);

#endif
