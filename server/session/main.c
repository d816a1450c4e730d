/* SPDX-License-Identifier: Apache-2.0 */
/* viscera-server: loads a scene file and runs it, publishing over Cyclone DDS.
 * This file is the command line; session/server_app.c what follows it. */
#include <stdio.h>
#include <stdlib.h>

#include "cli.h"
#include "cpu_pin.h"
#include "cpu_wake.h"
#include "dds/vdds.h"
#include "session/command_playout.h"
#include "session/server_app.h"
#include "vrt.h"

static void usage(FILE *f) {
  fprintf(f,
          "usage: viscera-server --scene FILE [options]\n"
          "  --scene FILE        scene file (YAML, see assets/scenes/README.md)\n"
          "  --domain N          DDS domain id 0..230 (default: $VISCERA_DOMAIN or 0)\n" CLI_HELP_INSECURE
          "  --partition P       session partition (default: " VDDS_DEFAULT_PARTITION ")\n"
          "  --duration S        stop after S seconds (default: run until SIGINT/SIGTERM)\n"
          "  --tool-timeout S    release a tool after S s without commands (default 0.5)\n"
          "  --command-playout N a tool's commands may wait up to N steps (0..%d, default %d) so that\n"
          "                      one comes into effect per step however they bunched on the way:\n"
          "                      the tool moves evenly and every command is answered; 0: the newest\n"
          "                      at once, skipping the others (docs/numerics.md §11.8)\n"
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
          "  --cpu-wake-latency US  while running, ask that no CPU take longer than US microseconds\n"
          "                      (0..%d) to wake from idle (PM QoS, /dev/cpu_dma_latency: needs\n"
          "                      root or write access; if refused: a warning, nothing else changes);\n"
          "                      0: idle CPUs poll instead of sleeping, so the step after each\n"
          "                      1 ms sleep keeps its caches (docs/numerics.md §11.5); costs power\n"
          "  --physics-cpus LIST keep the physics loop's thread(s) on these CPUs (taskset -c form:\n"
          "                      1, 0-3,6; DDS threads stay where they are); with the rest of the\n"
          "                      machine kept off them (taskset, cpusets) the loop has its cores\n"
          "                      to itself (docs/numerics.md §11.5); refused: a warning\n"
          "  --seats N           run N seats of the scene in this one process (1..%d), each\n"
          "                      its own session on partition P/seatKK (P: --partition); seats in\n"
          "                      one process share a core's caches better than one process per\n"
          "                      seat (docs/numerics.md §11.3); --checkpoint and --final-mesh PATH\n"
          "                      then name each seat's PATH.seatKK\n"
          "  --first-seat K      with --seats: the first seat's number (default 1): seats K..K+N-1,\n"
          "                      at most 99\n"
          "  --seat-threads K    with --seats: K physics threads (1..N), each stepping its share of\n"
          "                      the seats one after the other every tick (default: one per online\n"
          "                      CPU, at most N); fewer threads than seats step each seat closer\n"
          "                      to what it costs alone on a crowded machine, with less CPU\n"
          "                      (docs/numerics.md §11.4), but a seat's long step (a cut) delays\n"
          "                      the seats of its thread;\n"
          "                      K = N: a thread per seat\n"
          "  --quiet             only errors and warnings on stderr\n"
          "  --help              this text\n"
          "  --version           print the version and exit\n"
          "DDS configuration comes from CYCLONEDDS_URI (unset: deploy/cyclonedds-loopback.xml, one machine).\n"
          "Exit status: 0 done (or --check passed), 1 bad scene or runtime error, 2 usage error.\n",
          PLAYOUT_MAX_DEPTH, PLAYOUT_DEFAULT_DEPTH, CPU_WAKE_MAX_US, SERVER_APP_MAX_SEATS);
}

enum {
  OPT_SCENE = 's',
  OPT_DURATION = 't',
  OPT_FINAL_MESH = 'f',
  OPT_TOOL_TIMEOUT = 'T',
  OPT_CHECK = 'c',
  OPT_CHECKPOINT = 'K',
  OPT_CHECKPOINT_EVERY = 'E',
  OPT_RT_PRIORITY = 'R',
  OPT_SEATS = 'S',
  OPT_FIRST_SEAT = 'F',
  OPT_SEAT_THREADS = 'G',
  OPT_CPU_WAKE = 'W',
  OPT_PHYSICS_CPUS = 'P',
  OPT_COMMAND_PLAYOUT = 'Y'
};

/* A number of seconds: >= 0 when `zero_ok`, else > 0. */
static int seconds(const char *opt, const char *arg, int zero_ok, double *out) {
  char *end = NULL;
  *out = strtod(arg, &end);
  if (*end || !(*out > 0 || (zero_ok && *out == 0))) {
    fprintf(stderr, "viscera-server: --%s '%s' is not a number of seconds %s 0\n", opt, arg, zero_ok ? ">=" : ">");
    return 2;
  }
  return 0;
}

/* An integer lo..hi: 0, or 2 after a message naming the option and `what` it must be. */
static int integer(const char *opt, const char *arg, long lo, long hi, const char *what, long *out) {
  char *end = NULL;
  *out = strtol(arg, &end, 10);
  if (end == arg || *end || *out < lo || *out > hi) {
    fprintf(stderr, "viscera-server: --%s '%s' is not a %s %ld..%ld\n", opt, arg, what, lo, hi);
    return 2;
  }
  return 0;
}

static int on_option(void *ctx, int code, const char *arg) {
  server_app_options_t *o = ctx;
  switch (code) {
  case OPT_SCENE:
    o->scene_path = arg;
    return 0;
  case OPT_DURATION:
    return seconds("duration", arg, 1, &o->opts.duration);
  case OPT_TOOL_TIMEOUT:
    return seconds("tool-timeout", arg, 0, &o->opts.tool_timeout);
  case OPT_COMMAND_PLAYOUT: {
    long n;
    if (integer("command-playout", arg, 0, PLAYOUT_MAX_DEPTH, "number of steps", &n)) return 2;
    o->opts.command_playout = (size_t)n;
    return 0;
  }
  case OPT_FINAL_MESH:
    o->opts.final_mesh = arg;
    return 0;
  case OPT_CHECKPOINT:
    o->opts.checkpoint = arg;
    return 0;
  case OPT_CHECKPOINT_EVERY:
    return seconds("checkpoint-every", arg, 0, &o->opts.checkpoint_every);
  case OPT_RT_PRIORITY:
    if (vrt_parse_priority(arg, &o->opts.rt_priority)) {
      fprintf(stderr, "viscera-server: --rt-priority '%s' is not a SCHED_FIFO priority 1..99\n", arg);
      return 2;
    }
    return 0;
  case OPT_CPU_WAKE:
    return cpu_wake_option("viscera-server", arg, &o->cpu_wake_us);
  case OPT_PHYSICS_CPUS: {
    char why[160];
    if (cpu_pin_parse(arg, &o->physics_cpus, why, sizeof why)) {
      fprintf(stderr, "viscera-server: --physics-cpus: %s\n", why);
      return 2;
    }
    return 0;
  }
  case OPT_CHECK:
    o->check_only = 1;
    return 0;
  case OPT_SEATS: {
    long n;
    if (integer("seats", arg, 1, SERVER_APP_MAX_SEATS, "number of seats", &n)) return 2;
    o->seats = (int)n;
    return 0;
  }
  case OPT_SEAT_THREADS: {
    long n;
    if (integer("seat-threads", arg, 1, SERVER_APP_MAX_SEATS, "number of threads", &n)) return 2;
    o->seat_threads = (int)n;
    return 0;
  }
  case OPT_FIRST_SEAT: {
    long n;
    if (integer("first-seat", arg, 1, 99, "seat number", &n)) return 2;
    o->first_seat = (int)n;
    return 0;
  }
  }
  return 0; /* not reached: cli_parse passes only the codes above */
}

int main(int argc, char **argv) {
  vdds_set_role("server"); /* announced in the participant USER_DATA */
  static const struct option lo[] = {{"scene", required_argument, 0, OPT_SCENE},
                                     {"duration", required_argument, 0, OPT_DURATION},
                                     {"final-mesh", required_argument, 0, OPT_FINAL_MESH},
                                     {"tool-timeout", required_argument, 0, OPT_TOOL_TIMEOUT},
                                     {"command-playout", required_argument, 0, OPT_COMMAND_PLAYOUT},
                                     {"check", no_argument, 0, OPT_CHECK},
                                     {"checkpoint", required_argument, 0, OPT_CHECKPOINT},
                                     {"checkpoint-every", required_argument, 0, OPT_CHECKPOINT_EVERY},
                                     {"rt-priority", required_argument, 0, OPT_RT_PRIORITY},
                                     {"seats", required_argument, 0, OPT_SEATS},
                                     {"first-seat", required_argument, 0, OPT_FIRST_SEAT},
                                     {"seat-threads", required_argument, 0, OPT_SEAT_THREADS},
                                     {"cpu-wake-latency", required_argument, 0, OPT_CPU_WAKE},
                                     {"physics-cpus", required_argument, 0, OPT_PHYSICS_CPUS},
                                     {0, 0, 0, 0}};
  const cli_spec_t spec = {.program = "viscera-server",
                           .common = CLI_DOMAIN | CLI_DOMAIN_ENV | CLI_PARTITION | CLI_QUIET,
                           .shortopts = "s:d:p:t:f:T:R:cqh",
                           .options = lo,
                           .option = on_option,
                           .usage = usage};
  server_app_options_t o = {
      .seats = 0,
      .first_seat = 0,
      .cpu_wake_us = -1,
      .opts = {.duration = 0, .tool_timeout = 0.5, .command_playout = PLAYOUT_DEFAULT_DEPTH, .checkpoint_every = 1.0}};
  cli_common_t common = {0};
  int rc = cli_parse(&spec, argc, argv, &common, &o);
  if (rc != CLI_RUN) return rc;
  o.opts.domain = common.domain;
  o.opts.partition = common.partition;
  o.opts.quiet = common.quiet;
  if (o.physics_cpus.count) o.opts.physics_cpus = &o.physics_cpus;
  if (!o.scene_path) {
    fprintf(stderr, "viscera-server: --scene FILE is required\n");
    usage(stderr);
    return 2;
  }
  if (o.first_seat && !o.seats) {
    fprintf(stderr, "viscera-server: --first-seat needs --seats\n");
    return 2;
  }
  if (o.seat_threads && !o.seats) {
    fprintf(stderr, "viscera-server: --seat-threads needs --seats\n");
    return 2;
  }
  if (o.seat_threads > o.seats) {
    fprintf(stderr, "viscera-server: --seat-threads %d is more than the %d seats\n", o.seat_threads, o.seats);
    return 2;
  }
  if (!o.first_seat) o.first_seat = 1;
  if (o.seats && o.first_seat + o.seats - 1 > 99) {
    fprintf(stderr, "viscera-server: --seats %d from --first-seat %d goes past seat 99\n", o.seats, o.first_seat);
    return 2;
  }
  /* Held for the whole run, released at exit (main owns it: machine-wide). */
  cpu_wake_t wake = {.fd = -1};
  if (o.cpu_wake_us >= 0 && !o.check_only) {
    cpu_wake_hold(&wake, o.cpu_wake_us);
    cpu_wake_report(&wake, "server", stderr);
  }
  rc = server_app_run(&o);
  cpu_wake_release(&wake);
  return rc;
}
