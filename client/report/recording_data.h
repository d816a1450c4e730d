/* SPDX-License-Identifier: Apache-2.0 */
/* recording_data: everything a report needs from one recording, decoded
 * into plain arrays and measures (see measures.h for the definitions).
 *
 * Loading salvages: a truncated, damaged or still-being-written recording
 * yields what is readable plus warnings saying what was lost; only a file
 * that is not a viscera recording at all, or one with no tool samples,
 * fails (clear error naming the file). Samples that do not decode with this
 * build's types (e.g. events of a kind added later) are counted and warned
 * about, never fatal. Thresholds come from the recorded SceneInfo (ToolInfo
 * st/mpf/sft); crossings from the recorded SessionEvents, or from the
 * replayed force trace when the recording has no events. */
#ifndef VISCERA_REPORT_RECORDING_DATA_H
#define VISCERA_REPORT_RECORDING_DATA_H

#include <stdbool.h>
#include <stddef.h>

#include "training/measures.h"
#include "recording/recfile.h"
#include "verr.h"

#define REP_MAX_TOOLS 8
#define REP_MAX_TASKS 32
/* A silence longer than this (s) is a gap: the server releases a silent
 * tool after 0.5 s by default, so a longer pause restarts the path. */
#define REP_GAP_S 0.5

/* One cut of a scalpel, from the server's CUT_BEGIN / CUT_END events:
 * simulated times (NAN: that event is not in the recording, e.g. a cut still
 * going when the recording ended), the topology changes it made and the
 * server's own words at its end (vertex count, incision width). */
typedef struct rep_cut {
  double t_begin, t_end; /* s */
  int tool, organ;
  double changes;   /* NAN until its end */
  char result[257]; /* SessionEvent.text is string<256> */
} rep_cut_t;

typedef struct rep_tool {
  bool present; /* has samples or a ToolInfo */
  char name[72];
  double levels[THR_COUNT]; /* N, 0 = not set */
  rep_force_sample_t *force;
  size_t nforce, capforce;
  rep_pos_sample_t *cmd; /* ToolCommand positions, t = writer's source time */
  size_t ncmd, capcmd;
  rep_pos_sample_t *proxy; /* ContactFeedback proxy positions, t = simulated time */
  size_t nproxy, capproxy;
  rep_force_measures_t fm;
  double path_length; /* m */
} rep_tool_t;

/* The measures of a recording, summed over its tools as the server's
 * Metrics sums them. NAN where a measure cannot be computed. */
typedef struct rep_summary {
  double peak_force, mean_contact_force, contact_time;
  double time_above[THR_COUNT];
  double crossings[THR_COUNT]; /* upward crossings */
  bool crossings_from_events;  /* false: recomputed from the force trace */
  double path_length;
  double time_to_first_contact; /* s, first motion to first contact */
  double operation_time;        /* s, first motion to the end of the last contact */
  double duration;              /* s of simulated time covered by feedback */
  double levels[THR_COUNT];     /* of the first tool with thresholds */
} rep_summary_t;

typedef struct rep_recording {
  char path[512];
  char label[64];
  char seat[128];      /* the partition this section covers, "" = the whole file */
  char identity[1024]; /* who trained: seat, station, the trainee's process */
  recfile_session_t session;
  char scene[72];
  double physics_dt;
  bool have_scene_info;
  rep_tool_t tools[REP_MAX_TOOLS];
  int ntools; /* highest present tool id + 1 */
  uint32_t event_crossings[THR_COUNT];
  size_t nevents;
  rep_cut_t *cuts; /* in the order they began */
  size_t ncuts, capcuts;
  rep_task_event_t *task_events;
  size_t ntask_events, captask_events;
  rep_task_t tasks[REP_MAX_TASKS];
  size_t ntasks;
  bool have_metrics; /* the server's own last Metrics, for comparison */
  double metrics_time_above[THR_COUNT], metrics_contact_time, metrics_mean_force, metrics_peak, metrics_path;
  rep_summary_t sum;
  bool damaged;        /* salvage: part of the file was unreadable */
  char warnings[2048]; /* one per line, "" when none */
} rep_recording_t;

/* Loads and computes. With `seat` (a partition, e.g. "lab/seat02") only the
 * samples of writers in that partition count: one seat of a lab recorded
 * with a partition pattern; NULL takes every sample. Returns 0 (possibly
 * with warnings), or -1 with err naming the file; `r` must be freed with
 * rep_recording_free either way. */
int rep_recording_load(rep_recording_t *r, const char *path, const char *label, const char *seat, verr_t *err);

/* The seats of a recording: the distinct partitions its ContactFeedback
 * writers (the servers) wrote in, sorted, at most `max` of 128 bytes each.
 * Returns how many (0: none known), or -1 with err. */
int rep_recording_seats(const char *path, char (*seats)[128], int max, verr_t *err);
void rep_recording_free(rep_recording_t *r);

#endif
