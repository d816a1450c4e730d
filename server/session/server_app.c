/* SPDX-License-Identifier: Apache-2.0 */
/* viscera-server after its options: scene check or session run, then the
 * summary lines on stderr and stdout (SUMMARY, PUBLISHED, PALPATION, TOOL,
 * TASK, OBJECT) that scripts read. */
#include "session/server_app.h"

#include <inttypes.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <unistd.h>

#include "data_path.h"
#include "dds/vdds.h"
#include "scene.h"
#include "session/scene_check.h"
#include "session/seat_group.h"
#include "vsignal.h"

static volatile sig_atomic_t g_stop = 0;
static void on_signal(int sig) {
  (void)sig;
  g_stop = 1;
}

/* --check: build the models and print what each organ runs. */
static int check_scene(const scene_t *scene) {
  verr_t err;
  static runtime_t rt;
  /* Timed with every node moving (scene_check.h): regional sleeping off. */
  static scene_t awake;
  awake = *scene;
  for (size_t i = 0; i < awake.norgans; i++) awake.organs[i].solver.region_force = 0;
  if (runtime_init(&rt, &awake, &err)) {
    fprintf(stderr, "viscera-server: %s\n", err.msg);
    return 1;
  }
  printf("scene '%s': %zu organ(s), %zu tool(s), dt %.3g s\n", scene->name, scene->norgans, scene->ntools, scene->dt);
  for (size_t i = 0; i < rt.norgans; i++) {
    const organ_rt_t *o = &rt.organs[i];
    const model_t *m = o->model;
    /* "stable dt inf": the scheme is unconditionally stable (implicit). */
    printf("  organ '%s': model %s, integrator %s, %zu nodes, %zu tets, surface %zu vertices / %zu triangles, "
           "%d sub-step(s), stable dt %.3g ms\n",
           o->cfg->name, m->ops->name, o->cfg->integrator, m->nnodes, m->ntets, m->nsurf, m->nsurf_tris, m->substeps,
           m->stable_dt * 1e3);
    if (o->mesh_note[0]) printf("  organ '%s': mesh repaired: %s\n", o->cfg->name, o->mesh_note);
  }
  /* Warnings only (scene_check.h): real time at this dt, organ sizes. */
  scene_check_sizes(&rt, stderr);
  scene_check_cost(&rt, stdout, stderr);
  runtime_destroy(&rt);
  return 0;
}

/* The run's figures on stderr, for a person. */
static void print_stats(const scene_t *scene, const server_opts_t *opts, const server_stats_t *s) {
  fprintf(stderr,
          "server: %" PRIu64 " steps, step time median %.1f us p99 %.1f us max %.1f us, %" PRIu64 " overruns, %" PRIu64
          " rollbacks\n",
          s->steps, s->step_us_median, s->step_us_p99, s->step_us_max, s->overruns, s->rollbacks);
  fprintf(stderr, "server: step CPU time median %.1f us p99 %.1f us; %.3f simulated s per wall s\n",
          s->step_cpu_us_median, s->step_cpu_us_p99, s->realtime_ratio);
  fprintf(stderr,
          "server: step CPU split: tissue (contact and organs) median %.1f us p99 %.1f us; the rest (commands, "
          "feedback, inputs, frames) median %.1f us p99 %.1f us\n",
          s->step_tissue_cpu_us_median, s->step_tissue_cpu_us_p99, s->step_other_cpu_us_median,
          s->step_other_cpu_us_p99);
  if (scene->sleep_speed > 0)
    fprintf(stderr,
            "server: organs slept %" PRIu64 " times, woke %" PRIu64 " times; every organ asleep in %" PRIu64
            " of %" PRIu64 " steps (%.1f %%); steps with an organ awake (%zu recent): wall median %.1f us p99 %.1f "
            "us, CPU median %.1f us p99 %.1f us\n",
            s->organ_sleeps, s->organ_wakes, s->steps_all_asleep, s->steps,
            s->steps ? 100.0 * (double)s->steps_all_asleep / (double)s->steps : 0.0, s->awake_samples,
            s->awake_step_us_median, s->awake_step_us_p99, s->awake_step_cpu_us_median, s->awake_step_cpu_us_p99);
  if (s->region_organs && s->awake_steps)
    fprintf(stderr,
            "server: physics work per step with an organ awake (%" PRIu64 " steps): %.1f node updates, %.1f spring "
            "blocks (regional sleeping, %d organ(s)); tissue CPU mean %.1f us\n",
            s->awake_steps, (double)s->region_node_updates / (double)s->awake_steps,
            (double)s->region_block_evals / (double)s->awake_steps, s->region_organs,
            (double)s->awake_tissue_ns * 1e-3 / (double)s->awake_steps);
  fprintf(stderr, "server: %" PRIu64 " tool commands applied, %" PRIu64 " rejected (", s->commands, s->rejected_total);
  for (int v = 1; v < TOOLCMD_VERDICT_COUNT; v++)
    fprintf(stderr, "%s%s: %" PRIu64, v > 1 ? ", " : "", tool_command_verdict_str((tool_cmd_verdict_t)v),
            s->rejected[v]);
  fprintf(stderr, ")\n");
  if (s->commands)
    fprintf(stderr,
            "server: command playout (up to %zu step(s)): %" PRIu64 " commands waited a step or more to keep the "
            "tool's path even, %" PRIu64 " superseded in bunches beyond it, %" PRIu64 " dropped to catch up\n",
            s->playout_depth, s->commands_delayed, s->commands_superseded, s->commands_caught_up);
  if (s->gate_out_of_range || s->gate_refused || s->gate_blocked || s->commands_stale)
    fprintf(stderr,
            "server: intake gate dropped %" PRIu64 " for tools not in the scene, %" PRIu64 " malformed, %" PRIu64
            " from writers refused for the tool; %" PRIu64 " commands older than their writer's last skipped\n",
            s->gate_out_of_range, s->gate_refused, s->gate_blocked, s->commands_stale);
  if (opts->checkpoint)
    fprintf(stderr, "server: %" PRIu64 " checkpoint(s) written to %s%s\n", s->checkpoints_written, opts->checkpoint,
            s->resumed ? " (this run resumed from it)" : "");
  if (s->liveliness_blips)
    fprintf(stderr,
            "server: %" PRIu64 " client liveliness lapse(s) while still sending (kept, see liveliness_watch.h)\n",
            s->liveliness_blips);
  if (s->deltas_skipped)
    fprintf(stderr, "server: %" PRIu64 " MeshDelta frames written, %" PRIu64 " skipped (unchanged mesh)\n",
            s->published[VT_MESH_DELTA], s->deltas_skipped);
}

/* The run's figures on stdout, one line per kind, for scripts. */
static void print_summary(const scene_t *scene, const server_stats_t *s) {
  printf("SUMMARY steps=%" PRIu64 " peak_force=%.3f rejected=%" PRIu64 " rollbacks=%" PRIu64 " step_us_median=%.1f\n",
         s->steps, s->peak_force, s->rejected_total, s->rollbacks, s->step_us_median);
  /* The ToolCommand intake and the process's own clock and memory (issue
   * 15.1): a flood test judges by these, never by wall time. */
  printf("INTAKE commands=%" PRIu64 " rejected=%" PRIu64 " gate_out_of_range=%" PRIu64 " gate_refused=%" PRIu64
         " gate_blocked=%" PRIu64 " stale=%" PRIu64 " steps=%" PRIu64 " sim_time=%.3f overruns=%" PRIu64
         " step_cpu_us_median=%.1f step_cpu_us_p99=%.1f rss_start_kb=%ld rss_max_kb=%ld\n",
         s->commands, s->rejected_total, s->gate_out_of_range, s->gate_refused, s->gate_blocked, s->commands_stale,
         s->steps, s->sim_time, s->overruns, s->step_cpu_us_median, s->step_cpu_us_p99, s->rss_start_kb, s->rss_max_kb);
  /* What went on the wire, per topic, so a recording can be checked for drops. */
  printf("PUBLISHED");
  for (int t = 0; t < VT_COUNT; t++)
    if (t != VT_TOOL_COMMAND) printf(" %s=%" PRIu64, vdds_topic_name((vdds_topic_id_t)t), s->published[t]);
  printf("\n");
  /* Trainee measures per tool (docs/methods.md B ch. 6); levels of 0 are unset. */
  for (size_t t = 0; t < s->ntools; t++) {
    const thr_tracker_t *tr = &s->thr[t];
    printf("PALPATION tool=%s contact_time=%.3f mean_contact_force=%.4f peak_force=%.4f path_length=%.4f",
           scene->tools[t].name, tr->contact_time, thr_mean_contact_force(tr), tr->peak_force, tr->path_length);
    for (int k = 0; k < THR_COUNT; k++)
      printf(" %s=%.3f time_above_%s=%.3f crossings_%s=%u", thr_name((thr_id_t)k), tr->level[k], thr_name((thr_id_t)k),
             tr->time_above[k], thr_name((thr_id_t)k), tr->crossings[k]);
    printf("\n");
  }
  /* Per tool and per task (issue 4; docs/methods.md A Table 2 operation times). */
  for (size_t t = 0; t < s->ntools; t++) {
    const viscera_ToolMetrics *m = &s->tools[t];
    printf("TOOL tool=%s kind=%s peak_force=%.4f contact_time=%.3f path_length=%.4f exploration_time=%.3f grasps=%u "
           "grasp_time=%.3f tasks=%u/%u operation_time=%.3f\n",
           scene->tools[t].name, scene->tools[t].kind, m->peak_force, m->contact_time, m->path_length,
           m->exploration_time, m->grasps, m->grasp_time, m->tasks_completed, m->tasks_total, m->operation_time);
  }
  for (size_t i = 0; i < s->ntasks; i++) {
    const task_rt_t *k = &s->tasks[i];
    printf("TASK task=%s kind=%s tool=%s state=%s operation_time=%.3f\n", scene->tasks[i].name, scene->tasks[i].kind,
           scene->tools[scene->tasks[i].tool].name,
           k->completed ? "completed"
           : k->started ? "started"
                        : "not_started",
           task_operation_time(k, s->sim_time));
  }
  for (size_t i = 0; i < scene->nobjects; i++)
    printf("OBJECT object=%s removed=%d\n", scene->objects[i].name, s->stone_removed[i]);
}

/* One seat of a multi-seat process. */
typedef struct seat_run {
  server_opts_t opts;
  char partition[128];
  char tag[160];                                                         /* its log lines' prefix: "server P/seatKK" */
  char checkpoint[SERVER_APP_PATH_MAX], final_mesh[SERVER_APP_PATH_MAX]; /* the seat's own files */
  server_stats_t st;
} seat_run_t;

/* One physics thread and the seats it steps (seat_group.h). */
typedef struct group_run {
  seat_group_member_t *m;
  int n;
  char name[32]; /* the thread's, for ps and top (the kernel keeps 15 characters) */
} group_run_t;

static void *group_main(void *arg) {
  group_run_t *g = arg;
  prctl(PR_SET_NAME, g->name, 0, 0, 0);
  seat_group_run(g->m, g->n, &g_stop);
  return NULL;
}

/* A seat's own file: PATH.seatKK (server_app.h); NULL stays NULL. Returns
 * 0, or -1 when it does not fit. */
static int seat_file(char out[SERVER_APP_PATH_MAX], const char *path, int seat, const char **set) {
  if (!path) return 0;
  int len = snprintf(out, SERVER_APP_PATH_MAX, "%s.seat%02d", path, seat);
  if (len < 0 || len >= SERVER_APP_PATH_MAX) return -1;
  *set = out;
  return 0;
}

/* Seat k's options: its partition P/seatKK, log tag and files. Returns 0,
 * or -1 (said on stderr) when a name does not fit. */
static int seat_options(seat_run_t *r, const server_app_options_t *o, int k, pthread_mutex_t *lock) {
  const char *base = o->opts.partition ? o->opts.partition : VDDS_DEFAULT_PARTITION;
  r->opts = o->opts;
  int len = snprintf(r->partition, sizeof r->partition, "%s/seat%02d", base, o->first_seat + k);
  if (len < 0 || (size_t)len >= sizeof r->partition) {
    fprintf(stderr, "viscera-server: partition '%s' too long for its seats\n", base);
    return -1;
  }
  r->opts.partition = r->partition;
  snprintf(r->tag, sizeof r->tag, "server %s", r->partition);
  r->opts.log_tag = r->tag;
  r->opts.dds_setup_lock = lock;
  if (seat_file(r->checkpoint, o->opts.checkpoint, o->first_seat + k, &r->opts.checkpoint) ||
      seat_file(r->final_mesh, o->opts.final_mesh, o->first_seat + k, &r->opts.final_mesh)) {
    fprintf(stderr, "viscera-server: --checkpoint / --final-mesh path too long for its seats\n");
    return -1;
  }
  return 0;
}

/* --seats N (also 1: the seat's partition is P/seatKK): the sessions on
 * K physics threads (--seat-threads; default one per online CPU, at most
 * one per seat), each stepping a contiguous group of seats, then each
 * seat's figures. */
static int run_seats(const scene_t *scene, const server_app_options_t *o) {
  const int n = o->seats;
  int kt = o->seat_threads;
  if (kt <= 0) {
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    kt = cpus > 0 && cpus < n ? (int)cpus : n;
  }
  if (kt > n) kt = n;
  seat_run_t *seats = calloc((size_t)n, sizeof *seats);
  seat_group_member_t *m = calloc((size_t)n, sizeof *m);
  group_run_t *g = calloc((size_t)kt, sizeof *g);
  pthread_t *th = calloc((size_t)kt, sizeof *th);
  pthread_mutex_t dds_setup_lock = PTHREAD_MUTEX_INITIALIZER; /* server.h: opts.dds_setup_lock */
  int rc = 0;
  if (!seats || !m || !g || !th) {
    fprintf(stderr, "viscera-server: out of memory for %d seats\n", n);
    rc = 1;
  }
  for (int k = 0; k < n && !rc; k++) {
    if (seat_options(&seats[k], o, k, &dds_setup_lock)) rc = 1;
    m[k] = (seat_group_member_t){
        .scene = scene, .opts = &seats[k].opts, .name = seats[k].partition, .stats = &seats[k].st, .rc = 1};
  }
  int threads = 0;
  if (!rc) {
    /* A thread's default stack follows RLIMIT_STACK; a session keeps its
     * runtime (tens of kB per organ and tool) on it, as the main thread does. */
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    pthread_attr_setstacksize(&attr, (size_t)16 << 20);
    for (int t = 0; t < kt; t++) {
      int lo = t * n / kt, hi = (t + 1) * n / kt, a = o->first_seat + lo, b = o->first_seat + hi - 1;
      g[t] = (group_run_t){.m = m + lo, .n = hi - lo};
      if (a == b)
        snprintf(g[t].name, sizeof g[t].name, "seat%02d", a);
      else
        snprintf(g[t].name, sizeof g[t].name, "seats%02d-%02d", a, b);
      int e = pthread_create(&th[t], &attr, group_main, &g[t]);
      if (e) { /* the seats already started keep serving */
        fprintf(stderr, "viscera-server: seats %d-%d not started: %s\n", a, o->first_seat + n - 1, strerror(e));
        rc = 1;
        break;
      }
      threads++;
    }
    pthread_attr_destroy(&attr);
  }
  for (int t = 0; t < threads; t++) pthread_join(th[t], NULL);
  /* A seat that did not start was reported at once (seat_group.h); the
   * others served: their figures. */
  fflush(stdout); /* what the run printed goes before the first seat's block */
  for (int t = 0; t < threads; t++)
    for (int i = 0; i < g[t].n; i++) {
      const seat_group_member_t *mk = &g[t].m[i];
      int k = (int)(mk - m);
      if (mk->rc) {
        rc = 1;
        continue;
      }
      /* Seat by seat, stdout flushed at each seat's end: a block-buffered
       * stdout in the same file as stderr otherwise spills a flush into
       * the middle of a line, and deploy/seat_logs.sh, which splits the
       * log at each seat's header, hands a seat's figures to the seat
       * before it. */
      fprintf(stderr, "server: seat '%s' (%d of %d):\n", seats[k].partition, k + 1, n);
      print_stats(scene, &seats[k].opts, &seats[k].st);
      printf("SEAT partition=%s index=%d of=%d\n", seats[k].partition, k + 1, n);
      print_summary(scene, &seats[k].st);
      fflush(stdout);
    }
  pthread_mutex_destroy(&dds_setup_lock);
  free(seats);
  free(m);
  free(g);
  free(th);
  return rc;
}

int server_app_run(const server_app_options_t *o) {
  static scene_t scene;
  verr_t err;
  /* Installed data (data_path.h): "--scene default.yaml" works from any
   * directory; a path that exists as given is used as given. */
  char scene_path[DATA_PATH_MAX];
  if (data_path_resolve(o->scene_path, "assets/scenes", scene_path, sizeof scene_path) == 0 &&
      strcmp(scene_path, o->scene_path) && !o->opts.quiet)
    fprintf(stderr, "viscera-server: scene %s found as %s\n", o->scene_path, scene_path);
  if (scene_load(scene_path, &scene, &err)) {
    fprintf(stderr, "viscera-server: %s\n", err.msg);
    return 1;
  }
  if (o->check_only) return check_scene(&scene);
  vsignal_on_stop(on_signal, 0);
  if (o->seats > 0) return run_seats(&scene, o);
  server_stats_t st;
  if (server_run(&scene, &o->opts, &g_stop, &st, &err)) {
    fprintf(stderr, "viscera-server: %s\n", err.msg);
    return 1;
  }
  print_stats(&scene, &o->opts, &st);
  print_summary(&scene, &st);
  return 0;
}
