/* SPDX-License-Identifier: Apache-2.0 */
/* resim_schedule: which ToolCommand was in effect at every server step of a
 * recorded session, rebuilt from what the recorder stored.
 *
 * What the server does (server.c): before step k it takes every pending
 * ToolCommand and applies the last valid one per tool (runtime_set_tool
 * only overwrites the tool's target, so the state depends on that one
 * command alone); after step k it publishes one ContactFeedback per active
 * tool with cmd_seq = that command's seq and sim_time_ns = k dt. A tool
 * silent for --tool-timeout is released before a step: a CLIENT_LOST
 * SessionEvent stamped with the previous step's time e, so the tool is
 * inactive from step e + 1 until a new command reactivates it.
 *
 * So a feedback sample at step k names the command of step k exactly. The
 * ContactFeedback topic is best-effort, so samples can be missing; each gap
 * between two known steps (k1, seq s1) and (k2, s2) is filled:
 *   - a release at e in [k1, k2): s1 up to e, inactive after (exact, the
 *     tool was silent for the timeout before e);
 *   - s1 == s2: s1 throughout (exact: a client's seq only grows);
 *   - s1 != s2: ambiguous. Each step takes the newest recorded command with
 *     seq in (s1, s2] written (source timestamp) before the step's estimated
 *     wall time (interpolated between the feedback timestamps of k1 and k2),
 *     else s1; the step is counted as ambiguous.
 * Before a tool's first feedback it is inactive; after its last one it
 * holds that command (up to a release, if one follows).
 * A seq the recorder did not store (ToolCommand is best-effort too) is
 * replaced by the nearest recorded command below it (above if none) and
 * counted. Nothing here trusts the input: duplicates, unsorted arrays and
 * steps beyond the range are handled, never indexed out of bounds. */
#ifndef VISCERA_RESIM_SCHEDULE_H
#define VISCERA_RESIM_SCHEDULE_H

#include <stddef.h>
#include <stdint.h>

#include "verr.h"

/* A recorded ContactFeedback of one tool. */
typedef struct resim_fb {
  uint64_t step;   /* round(sim_time_ns / dt_ns) */
  uint64_t seq;    /* cmd_seq */
  int64_t wall_ns; /* source timestamp (server's clock), 0 unknown */
} resim_fb_t;

/* A recorded ToolCommand of one tool. */
typedef struct resim_cmd {
  uint64_t seq;
  int64_t wall_ns; /* source timestamp (client's clock), 0 unknown */
  double pos[3];   /* the float position as sent, widened as the server does */
  double max_force;
} resim_cmd_t;

typedef struct resim_tool_input {
  resim_fb_t *fb; /* sorted in place by step */
  size_t nfb;
  resim_cmd_t *cmd; /* sorted in place by seq */
  size_t ncmd;
  uint64_t *release; /* CLIENT_LOST event steps e (release before e + 1); sorted in place */
  size_t nrelease;
} resim_tool_input_t;

typedef struct resim_schedule_stats {
  uint64_t feedback_steps;   /* steps named by a feedback sample */
  uint64_t bridged_steps;    /* missing feedback, command certain (same seq both sides or before a release) */
  uint64_t ambiguous_steps;  /* missing feedback, command estimated */
  uint64_t gaps;             /* runs of missing feedback inside an active stretch */
  uint64_t missing_commands; /* scheduled seqs not in the recording, replaced by the nearest */
  uint64_t conflicts;        /* two feedback samples for one step naming different seqs (the later wins) */
  uint64_t releases;         /* releases honoured */
} resim_schedule_stats_t;

/* Fills out[0..nsteps] (out[k]: index into in->cmd of the command in effect
 * at step k, -1 inactive; out[0] is the initial state, always -1) for one
 * tool and adds to *st. Returns 0, or -1 with err when feedback names
 * commands but none was recorded. */
int resim_schedule_build(resim_tool_input_t *in, uint64_t nsteps, int32_t *out, resim_schedule_stats_t *st,
                         verr_t *err);

#endif
