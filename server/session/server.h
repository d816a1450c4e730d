/* SPDX-License-Identifier: Apache-2.0 */
/* server: the scene runtime wired to DDS. Reads ToolCommand, steps physics in
 * real time at the scene's fixed dt, publishes ContactFeedback every step,
 * MeshDelta at publish_hz, MeshState keyframes, SceneInfo, SessionEvent and
 * Metrics (once per second). One thread; DDS reads never block the loop. */
#ifndef VISCERA_SERVER_H
#define VISCERA_SERVER_H

#include <pthread.h>
#include <signal.h>
#include <stdint.h>

#include "dds/vdds.h"
#include "runtime/scene_runtime.h"
#include "cpu_pin.h"
#include "session/mesh_publisher.h"
#include "training/thresholds.h"
#include "viscera.h"

typedef struct server_opts {
  int domain;
  const char *partition;
  double duration;        /* s of wall time; 0 = until stopped */
  const char *final_mesh; /* write exact positions of the last published frame here (OBJ) */
  int quiet;
  double tool_timeout;           /* s without a command before a tool is released */
  size_t command_playout;        /* steps a command may wait for its step (command_playout.h); 0: the newest at once */
  const char *checkpoint;        /* state file: resumed from at start when it fits the scene, written periodically */
  double checkpoint_every;       /* s of simulated time between checkpoints */
  int rt_priority;               /* 1..99: the step loop's thread runs SCHED_FIFO at it (vrt.h); 0 = normal */
  const cpu_pin_t *physics_cpus; /* the step loop's thread kept on these CPUs (cpu_pin.h); NULL: anywhere.
                                    Owned by the caller */
  const char *log_tag; /* the log lines' "TAG: " (NULL: "server"); a seat's own among several (server_app.h) */
  /* Sessions sharing a process (server_app.h) share this lock, held while a
   * session creates its participant, readers and writers: with DDS Security
   * on, Cyclone 0.10.2 failed a participant created at the same time as
   * another of the process ("get_identity_token: Invalid handle provided").
   * NULL: one session, no lock. Owned by the caller. */
  pthread_mutex_t *dds_setup_lock;
} server_opts_t;

typedef struct server_stats {
  uint64_t checkpoints_written;
  int resumed; /* started from a checkpoint */
  uint64_t steps, overruns, rollbacks, rejected[TOOLCMD_VERDICT_COUNT], rejected_total, commands;
  uint64_t liveliness_blips; /* client liveliness lapses that were not a lost client */
  /* ToolCommand intake (issue 15.1, 14.2): samples the gate dropped before
   * DDS stored them (also counted in rejected[]), by cause; commands not
   * applied because their writer had already sent a newer one. */
  uint64_t gate_out_of_range, gate_refused, gate_blocked, commands_stale;
  /* The playout (command_playout.h) at close, summed over the tools:
   * commands put into effect a step or more after their take, never put
   * into effect (a bunch beyond the depth), dropped to give latency back. */
  size_t playout_depth;
  uint64_t commands_delayed, commands_superseded, commands_caught_up;
  long rss_start_kb, rss_max_kb; /* resident set at the first step, and the largest seen at a metrics period */
  double peak_force;
  double step_us_median, step_us_p99, step_us_max;
  /* The same steps in this thread's CPU time: the work a step costs, apart
   * from time the scheduler gave to other processes (on a crowded machine
   * wall time grows while this stays put). */
  double step_cpu_us_median, step_cpu_us_p99;
  /* That CPU time split per step: the runtime's step (contact phase and
   * organs: the physics) and the rest (taking commands, writing feedback,
   * inputs, events and frames: mostly DDS). On a crowded machine both
   * grow (docs/numerics.md §11.2). Paused steps count as all "rest". */
  double step_tissue_cpu_us_median, step_tissue_cpu_us_p99, step_other_cpu_us_median, step_other_cpu_us_p99;
  double realtime_ratio; /* simulated s per wall s over the run */
  /* Organ sleeping (organ_sleep.h): steps in which every organ slept, over
   * the run, and the step times above restricted to the steps that
   * stepped an organ (the physics work), over the same recent steps. */
  uint64_t steps_all_asleep;
  uint64_t organ_sleeps, organ_wakes, organ_slept_steps; /* summed over the organs */
  int sleep_enabled;                                     /* the scene's sleep_speed > 0 */
  size_t awake_samples;                                  /* how many of the recent steps stepped an organ */
  double awake_step_us_median, awake_step_us_p99, awake_step_cpu_us_median, awake_step_cpu_us_p99;
  /* The physics work behind those steps, over the whole run: steps that
   * stepped an organ, their tissue CPU time summed (ns), and what regional
   * sleeping integrated in them (runtime/region_work.h; region_organs 0:
   * no organ sleeps by regions). Two runs' tissue times compare only at
   * equal work (docs/numerics.md §11.7). */
  uint64_t awake_steps, awake_tissue_ns;
  int region_organs;
  uint64_t region_node_updates, region_block_evals;
  size_t ntools;
  thr_tracker_t thr[SCENE_MAX_TOOLS];         /* palpation measures per tool at the end */
  viscera_ToolMetrics tools[SCENE_MAX_TOOLS]; /* per-tool measures at the end */
  size_t ntasks;
  task_rt_t tasks[SCENE_MAX_TASKS]; /* cfg points into the server's scene copy: use the index, not cfg */
  int stone_removed[SCENE_MAX_OBJECTS];
  double sim_time;              /* s simulated */
  uint64_t published[VT_COUNT]; /* samples written per topic (vdds ids), for drop accounting */
  uint64_t deltas_skipped;      /* MeshDelta frames not written: equal to the last one (mesh_publisher.h) */
} server_stats_t;

/* A session stepped by its caller: a thread that steps one or several
 * sessions each tick (seat_group.h: seat_group_run, and server_run for
 * one session). All calls on one session come from one thread (the one
 * that opened it); sessions of one process may be opened from several.
 *
 * server_open: the session's set-up (DDS entities, the runtime,
 * a checkpoint resumed when opts->checkpoint fits, the first keyframes and
 * SessionEvent). stats is written through to server_close and must outlive
 * the session; opts and scene must too. NULL with err when the session
 * cannot run (nothing is left open).
 *
 * A step is three calls, in order: server_step_begin(t0) takes the
 * commands and controls, runs the contact phase and writes the
 * ContactFeedback of the tools with a fresh command (t0: the tick's
 * monotonic ns); -1 when the session cannot go on (a scene rebuild
 * failed): the caller stops stepping it and closes it. server_step_tissue
 * steps the organs. server_step_end writes everything else (feedback not
 * sent early, events, frames, metrics), submits a due checkpoint and
 * returns the monotonic ns at which the step's publishing ended. Each
 * session's step time (stats) counts only its own phases' wall and thread
 * CPU time, so a caller may run other sessions' phases in between.
 *
 * server_close: final frame, metrics and event, the checkpoint and final
 * mesh, the stats filled in; frees the session. */
typedef struct server server_t;
enum { SERVER_RESYNC_NS = 100000000 }; /* a loop this far behind its ticks starts again from now */
server_t *server_open(const scene_t *scene, const server_opts_t *opts, server_stats_t *stats, verr_t *err);
int server_step_begin(server_t *s, uint64_t t0);
void server_step_tissue(server_t *s);
uint64_t server_step_end(server_t *s);
void server_close(server_t *s);
uint64_t server_dt_ns(const server_t *s); /* the scene's step */
void server_note_overrun(server_t *s);    /* its stats: the stepping thread fell behind and resynchronised */
/* The calling thread as a physics loop: on opts->physics_cpus when set
 * (cpu_pin.h; refused: a warning), SCHED_FIFO at opts->rt_priority when set
 * (vrt.h), timer slack 1 ns. Call after the sessions are open
 * (their DDS threads stay at normal priority). */
void server_thread_prepare(const server_opts_t *opts, const char *tag);

#endif
