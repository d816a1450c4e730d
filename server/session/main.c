/* viscera-server: loads a scene file and runs it, publishing over Cyclone DDS. */
#include <getopt.h>
#include <inttypes.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dds/vdds.h"
#include "scene.h"
#include "session/server.h"
#include "vrt.h"
#include "vsignal.h"

static volatile sig_atomic_t g_stop = 0;
static void on_signal(int sig) {
  (void)sig;
  g_stop = 1;
}

static void usage(FILE *f) {
  fprintf(f, "usage: viscera-server --scene FILE [options]\n"
             "  --scene FILE        scene file (YAML, see assets/scenes/README.md)\n"
             "  --domain N          DDS domain id 0..230 (default: $VISCERA_DOMAIN or 0)\n"
             "  --partition P       session partition (default: " VDDS_DEFAULT_PARTITION ")\n"
             "  --duration S        stop after S seconds (default: run until SIGINT/SIGTERM)\n"
             "  --tool-timeout S    release a tool after S s without commands (default 0.5)\n"
             "  --final-mesh PATH   on exit write the last published frame's exact positions (OBJ)\n"
             "  --checkpoint FILE   resume from FILE when it holds this scene's state (kill -9, crash), and\n"
             "                      write the state there every --checkpoint-every s and at exit\n"
             "  --checkpoint-every S  simulated seconds between checkpoints (default 1)\n"
             "  --check             load and validate the scene, build its models, print per organ the model,\n"
             "                      integrator, nodes, tetrahedra, sub-steps and stable dt, exit\n"
             "  --rt-priority N     run the physics loop's thread (only it; DDS threads stay normal)\n"
             "                      SCHED_FIFO at priority N (1..99) with memory locked (needs root,\n"
             "                      CAP_SYS_NICE or LimitRTPRIO; if refused: a warning naming the reason,\n"
             "                      normal priority)\n"
             "  --quiet             only errors and warnings on stderr\n"
             "  --help              this text\n"
             "DDS configuration comes from CYCLONEDDS_URI (deploy/cyclonedds-loopback.xml for one machine).\n");
}

int main(int argc, char **argv) {
  vdds_set_role("server"); /* announced in the participant USER_DATA */
  const char *scene_path = NULL;
  server_opts_t opts = {.domain = 0, .partition = NULL, .duration = 0, .tool_timeout = 0.5, .checkpoint_every = 1.0};
  verr_t err;
  if ((opts.domain = vdds_env_domain(&err)) < 0) {
    fprintf(stderr, "viscera-server: %s\n", err.msg);
    return 2;
  }
  int check_only = 0;
  static const struct option lo[] = {{"scene", required_argument, 0, 's'},
                                     {"domain", required_argument, 0, 'd'},
                                     {"partition", required_argument, 0, 'p'},
                                     {"duration", required_argument, 0, 't'},
                                     {"final-mesh", required_argument, 0, 'f'},
                                     {"tool-timeout", required_argument, 0, 'T'},
                                     {"check", no_argument, 0, 'c'},
                                     {"quiet", no_argument, 0, 'q'},
                                     {"checkpoint", required_argument, 0, 'K'},
                                     {"checkpoint-every", required_argument, 0, 'E'},
                                     {"rt-priority", required_argument, 0, 'R'},
                                     {"help", no_argument, 0, 'h'},
                                     {0, 0, 0, 0}};
  int c;
  while ((c = getopt_long(argc, argv, "s:d:p:t:f:T:R:cqh", lo, NULL)) != -1) {
    char *end = NULL;
    switch (c) {
    case 's':
      scene_path = optarg;
      break;
    case 'd':
      if ((opts.domain = vdds_parse_domain(optarg)) < 0) {
        fprintf(stderr, "viscera-server: --domain '%s' is not a domain id 0..230\n", optarg);
        return 2;
      }
      break;
    case 'p':
      opts.partition = optarg;
      break;
    case 't':
      opts.duration = strtod(optarg, &end);
      if (*end || !(opts.duration >= 0)) {
        fprintf(stderr, "viscera-server: --duration '%s' is not a number of seconds >= 0\n", optarg);
        return 2;
      }
      break;
    case 'T':
      opts.tool_timeout = strtod(optarg, &end);
      if (*end || !(opts.tool_timeout > 0)) {
        fprintf(stderr, "viscera-server: --tool-timeout '%s' is not a number of seconds > 0\n", optarg);
        return 2;
      }
      break;
    case 'f':
      opts.final_mesh = optarg;
      break;
    case 'K':
      opts.checkpoint = optarg;
      break;
    case 'E':
      opts.checkpoint_every = strtod(optarg, &end);
      if (*end || !(opts.checkpoint_every > 0)) {
        fprintf(stderr, "viscera-server: --checkpoint-every '%s' is not a number of seconds > 0\n", optarg);
        return 2;
      }
      break;
    case 'R':
      if (vrt_parse_priority(optarg, &opts.rt_priority)) {
        fprintf(stderr, "viscera-server: --rt-priority '%s' is not a SCHED_FIFO priority 1..99\n", optarg);
        return 2;
      }
      break;
    case 'c':
      check_only = 1;
      break;
    case 'q':
      opts.quiet = 1;
      break;
    case 'h':
      usage(stdout);
      return 0;
    default:
      usage(stderr);
      return 2;
    }
  }
  if (!scene_path) {
    fprintf(stderr, "viscera-server: --scene FILE is required\n");
    usage(stderr);
    return 2;
  }
  static scene_t scene;
  if (scene_load(scene_path, &scene, &err)) {
    fprintf(stderr, "viscera-server: %s\n", err.msg);
    return 1;
  }
  if (check_only) {
    static runtime_t rt;
    if (runtime_init(&rt, &scene, &err)) {
      fprintf(stderr, "viscera-server: %s\n", err.msg);
      return 1;
    }
    printf("scene '%s': %zu organ(s), %zu tool(s), dt %.3g s\n", scene.name, scene.norgans, scene.ntools, scene.dt);
    for (size_t i = 0; i < rt.norgans; i++) {
      const organ_rt_t *o = &rt.organs[i];
      const model_t *m = o->model;
      /* "stable dt inf": the scheme is unconditionally stable (implicit). */
      printf("  organ '%s': model %s, integrator %s, %zu nodes, %zu tets, surface %zu vertices / %zu triangles, "
             "%d sub-step(s), stable dt %.3g ms\n",
             o->cfg->name, m->ops->name, o->cfg->integrator, m->nnodes, m->ntets, m->nsurf, m->nsurf_tris, m->substeps,
             m->stable_dt * 1e3);
    }
    runtime_destroy(&rt);
    return 0;
  }
  vsignal_on_stop(on_signal, 0);
  server_stats_t st;
  if (server_run(&scene, &opts, &g_stop, &st, &err)) {
    fprintf(stderr, "viscera-server: %s\n", err.msg);
    return 1;
  }
  fprintf(stderr,
          "server: %" PRIu64 " steps, step time median %.1f us p99 %.1f us max %.1f us, %" PRIu64 " overruns, %" PRIu64
          " rollbacks\n",
          st.steps, st.step_us_median, st.step_us_p99, st.step_us_max, st.overruns, st.rollbacks);
  fprintf(stderr, "server: step CPU time median %.1f us p99 %.1f us; %.3f simulated s per wall s\n",
          st.step_cpu_us_median, st.step_cpu_us_p99, st.realtime_ratio);
  if (scene.sleep_speed > 0)
    fprintf(stderr,
            "server: organs slept %" PRIu64 " times, woke %" PRIu64 " times; every organ asleep in %" PRIu64
            " of %" PRIu64 " steps (%.1f %%); steps with an organ awake (%zu recent): wall median %.1f us p99 %.1f "
            "us, CPU median %.1f us p99 %.1f us\n",
            st.organ_sleeps, st.organ_wakes, st.steps_all_asleep, st.steps,
            st.steps ? 100.0 * (double)st.steps_all_asleep / (double)st.steps : 0.0, st.awake_samples,
            st.awake_step_us_median, st.awake_step_us_p99, st.awake_step_cpu_us_median, st.awake_step_cpu_us_p99);
  fprintf(stderr, "server: %" PRIu64 " tool commands applied, %" PRIu64 " rejected (", st.commands, st.rejected_total);
  for (int v = 1; v < TOOLCMD_VERDICT_COUNT; v++)
    fprintf(stderr, "%s%s: %" PRIu64, v > 1 ? ", " : "", tool_command_verdict_str((tool_cmd_verdict_t)v),
            st.rejected[v]);
  fprintf(stderr, ")\n");
  if (opts.checkpoint)
    fprintf(stderr, "server: %" PRIu64 " checkpoint(s) written to %s%s\n", st.checkpoints_written, opts.checkpoint,
            st.resumed ? " (this run resumed from it)" : "");
  if (st.liveliness_blips)
    fprintf(stderr,
            "server: %" PRIu64 " client liveliness lapse(s) while still sending (kept, see liveliness_watch.h)\n",
            st.liveliness_blips);
  if (st.deltas_skipped)
    fprintf(stderr, "server: %" PRIu64 " MeshDelta frames written, %" PRIu64 " skipped (unchanged mesh)\n",
            st.published[VT_MESH_DELTA], st.deltas_skipped);
  printf("SUMMARY steps=%" PRIu64 " peak_force=%.3f rejected=%" PRIu64 " rollbacks=%" PRIu64 " step_us_median=%.1f\n",
         st.steps, st.peak_force, st.rejected_total, st.rollbacks, st.step_us_median);
  /* What went on the wire, per topic, so a recording can be checked for drops. */
  printf("PUBLISHED");
  for (int t = 0; t < VT_COUNT; t++)
    if (t != VT_TOOL_COMMAND) printf(" %s=%" PRIu64, vdds_topic_name((vdds_topic_id_t)t), st.published[t]);
  printf("\n");
  /* Trainee measures per tool (seed 002 ch. 6); levels of 0 are unset. */
  for (size_t t = 0; t < st.ntools; t++) {
    const thr_tracker_t *tr = &st.thr[t];
    printf("PALPATION tool=%s contact_time=%.3f mean_contact_force=%.4f peak_force=%.4f path_length=%.4f",
           scene.tools[t].name, tr->contact_time, thr_mean_contact_force(tr), tr->peak_force, tr->path_length);
    for (int k = 0; k < THR_COUNT; k++)
      printf(" %s=%.3f time_above_%s=%.3f crossings_%s=%u", thr_name((thr_id_t)k), tr->level[k], thr_name((thr_id_t)k),
             tr->time_above[k], thr_name((thr_id_t)k), tr->crossings[k]);
    printf("\n");
  }
  /* Per tool and per task (issue 4; seed 000 Table 2 operation times). */
  for (size_t t = 0; t < st.ntools; t++) {
    const viscera_ToolMetrics *m = &st.tools[t];
    printf("TOOL tool=%s kind=%s peak_force=%.4f contact_time=%.3f path_length=%.4f exploration_time=%.3f grasps=%u "
           "grasp_time=%.3f tasks=%u/%u operation_time=%.3f\n",
           scene.tools[t].name, scene.tools[t].kind, m->peak_force, m->contact_time, m->path_length,
           m->exploration_time, m->grasps, m->grasp_time, m->tasks_completed, m->tasks_total, m->operation_time);
  }
  for (size_t i = 0; i < st.ntasks; i++) {
    const task_rt_t *k = &st.tasks[i];
    printf("TASK task=%s kind=%s tool=%s state=%s operation_time=%.3f\n", scene.tasks[i].name, scene.tasks[i].kind,
           scene.tools[scene.tasks[i].tool].name,
           k->completed ? "completed"
           : k->started ? "started"
                        : "not_started",
           task_operation_time(k, st.sim_time));
  }
  for (size_t i = 0; i < scene.nobjects; i++)
    printf("OBJECT object=%s removed=%d\n", scene.objects[i].name, st.stone_removed[i]);
  return 0;
}
