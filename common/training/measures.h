/* SPDX-License-Identifier: Apache-2.0 */
/* measures: the trainee measures of a report, computed from plain sample
 * arrays decoded from a recording (no I/O here, so tests feed synthetic
 * arrays).
 *
 * Force measures replay the ContactFeedback force magnitudes of one tool
 * through the server's own threshold tracker (training/thresholds.c), so the
 * hysteresis, "time above" and crossing rules are the server's by
 * construction, not a second implementation. Each sample stands for the
 * time since the previous one (its server step, dt_nominal when samples are
 * consecutive), so samples a loaded recorder lost are made up for by the
 * next one. A gap longer than `gap_s` counts dt_nominal only, unless the
 * tool was in contact on both sides of it: a tool the server released
 * (client silent) leaves the contact first, while a hole in mid-contact
 * can only be lost samples. A sample out of order counts dt_nominal.
 *
 * Definitions (docs/methods.md B ch. 6, docs/methods.md A Table 2):
 *   contact (exploration) time   time in contact, as the server's Metrics;
 *   time to first contact        from the first tool motion to the first
 *                                contact: reaching the feature (002 §6.6.2.2);
 *   operation time               from the first tool motion to the end of
 *                                the last contact (000 Table 2, per organ);
 *   path length                  sum of |p_i - p_{i-1}| over the tool
 *                                commands, restarting after a pause of
 *                                the client (not after samples the
 *                                recording lost: command seq tells);
 *   task time                    TASK_STARTED to TASK_COMPLETED of the same
 *                                task (events matched by the task id the
 *                                server puts in them; by name for events
 *                                without one). */
#ifndef VISCERA_REPORT_MEASURES_H
#define VISCERA_REPORT_MEASURES_H

#include <stddef.h>
#include <stdint.h>

#include "training/thresholds.h"

typedef struct rep_force_sample {
  double t;     /* s, simulated time of the server step */
  double force; /* N, |F| on the tool */
  int in_contact;
} rep_force_sample_t;

typedef struct rep_pos_sample {
  double t; /* s, any clock increasing with the samples (used for gaps only) */
  double p[3];
  uint64_t seq; /* writer's sequence number (ToolCommand.seq), 0 = unknown */
} rep_pos_sample_t;

typedef struct rep_force_measures {
  size_t samples;
  double peak_force;         /* N */
  double mean_contact_force; /* N, over the time in contact */
  double contact_time;       /* s */
  double time_above[THR_COUNT];
  uint32_t crossings[THR_COUNT]; /* upward crossings in the replayed trace */
  double first_t, last_t;        /* s, first and last sample time */
  double first_contact_t;        /* s, NAN when never in contact */
  double last_contact_end_t;     /* s, end of the last contact, NAN when none */
} rep_force_measures_t;

/* levels: ST, MPF, SFT in N (0 = not set). */
void rep_force_measures(const rep_force_sample_t *s, size_t n, const double levels[THR_COUNT], double dt_nominal,
                        double gap_s, rep_force_measures_t *m);

/* Path length, m, skipping non-finite positions. A step back in t breaks
 * the path; so does a silence longer than gap_s, unless seq shows the
 * writer kept sending (samples lost in between: the straight segment is
 * the best estimate of the way travelled). */
double rep_path_length(const rep_pos_sample_t *p, size_t n, double gap_s);

/* The time the tool first moved more than `eps` m from its first position,
 * NAN when it never did. */
double rep_first_motion(const rep_pos_sample_t *p, size_t n, double eps);

typedef enum rep_task_mark { REP_TASK_STARTED, REP_TASK_COMPLETED } rep_task_mark_t;

typedef struct rep_task_event {
  double t;
  rep_task_mark_t mark;
  int id; /* the scene's task index, -1 when the event carries none */
  char name[64];
  double value; /* completion: the operation time the server measured (s), NAN unknown */
} rep_task_event_t;

typedef struct rep_task {
  int id; /* -1: unknown, the task is known by name only */
  char name[64];
  double start, end; /* s; end = NAN when not completed */
  int started_seen;  /* 0: completed without a start event, start = session start */
} rep_task_t;

/* Pairs start and completion events by task id (by name when either has
 * no id), in time order. A completion that carries the server's operation
 * time (value) sets the start to end - value: the server starts a task's
 * clock at its tool's first command, a step before the event; a second
 * start of a running task restarts it. `session_start` stands in for a
 * missing start. Writes at most `cap` tasks (in order of first appearance)
 * and returns how many. */
size_t rep_tasks(const rep_task_event_t *ev, size_t n, double session_start, rep_task_t *out, size_t cap);

#endif
