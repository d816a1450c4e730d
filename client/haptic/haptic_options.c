/* SPDX-License-Identifier: Apache-2.0 */
#include "haptic_options.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "station.h"
#include "cli.h"
#include "cpu_wake.h"
#include "dds/vdds.h"
#include "vrt.h"

void haptic_usage(FILE *f) {
  fprintf(f,
          "usage: viscera-haptic --trajectory FILE [options]\n"
          "       viscera-haptic --device NAME [options]\n"
          "  --device NAME       scripted (default), dhd, hd or falcon; this build has: %s\n"
          "  --trajectory FILE   scripted device: play this path (t x y z [buttons] per line)\n"
          "  --loop              scripted device: play it over and over until --duration or a signal\n"
          "                      (the path must end where it begins)\n"
          "  --start-on-answer   scripted device: hold the path's first pose until the server first\n"
          "                      answers (a ContactFeedback for this tool), then play it from 0, so\n"
          "                      no part of it goes out before the server hears this client (its\n"
          "                      command reader matches a new writer some 0.1-0.5 s after the scene\n"
          "                      is seen); no answer within --wait-server s: it starts, with a warning\n"
          "  --device-index N    real devices: which one of that kind (default 0)\n"
          "  --workspace-scale S real devices: scene metres per device metre (default 1)\n"
          "  --workspace-offset X,Y,Z  real devices: scene position (m) of the device's\n"
          "                      workspace centre (default 0,0,0)\n"
          "  --tool N            tool index in the scene (default 0)\n"
          "  --station NAME      the station (person/seat) this device belongs to, announced with\n"
          "                      every command; a tool assigned to a station obeys only it\n"
          "                      (default: none, the anonymous station)\n"
          "  --domain N          DDS domain id (default: $VISCERA_DOMAIN or 0)\n" CLI_HELP_INSECURE
          "  --partition P       session partition (default: " VDDS_DEFAULT_PARTITION ")\n"
          "  --rate HZ           loop rate (default 1000)\n"
          "  --max-force N       device capability in newtons (default 4)\n"
          "  --max-stiffness K   device stiffness rating, N/m: the server's contact stiffness is\n"
          "                      rendered clamped to it (default 0: no stated limit)\n"
          "  --wait-server S     wait up to S s for the server's scene before starting (default 10)\n"
          "  --duration S        stop after S s (default: end of the trajectory + 0.5 s; with --loop\n"
          "                      until a signal)\n"
          "  --force-csv FILE    write t,x,y,z,fx,fy,fz,in_contact,energy_j,step_n per tick\n"
          "  --guide-rtt S       guiding hand: round trip to the peer station, s, at least (default 0;\n"
          "                      the client also takes twice its own round trip to the server, and\n"
          "                      twice the peer's commands' transit from their source timestamps)\n"
          "  --rt-priority N     run the loop thread (only it) SCHED_FIFO at priority N (1..99) with\n"
          "                      memory locked (needs root, CAP_SYS_NICE or LimitRTPRIO; if refused:\n"
          "                      a warning naming the reason, normal priority)\n"
          "  --cpu-wake-latency US  while running, ask that no CPU take longer than US microseconds\n"
          "                      (0..%d) to wake from idle (PM QoS: needs root or write access to\n"
          "                      /dev/cpu_dma_latency; if refused: a warning); 0: idle CPUs poll\n"
          "                      instead of sleeping, the loop wakes on time; costs power\n"
          "  --quiet             only the summary\n"
          "  --help              this text\n"
          "  --version           print the version and exit\n"
          "Exit status: 0 done (trajectory ended, --duration or SIGINT/SIGTERM), 1 device, DDS or\n"
          "output error (or no server within --wait-server), 2 usage error.\n",
          device_names(), CPU_WAKE_MAX_US);
}

enum {
  OPT_TRAJECTORY = 'j',
  OPT_TOOL = 'n',
  OPT_STATION = 's',
  OPT_RATE = 'r',
  OPT_MAX_FORCE = 'm',
  OPT_MAX_STIFFNESS = 'K',
  OPT_WAIT_SERVER = 'w',
  OPT_DURATION = 't',
  OPT_FORCE_CSV = 'f',
  OPT_RT_PRIORITY = 'R',
  OPT_DEVICE = 'D',
  OPT_DEVICE_INDEX = 'I',
  OPT_WORKSPACE_SCALE = 'S',
  OPT_WORKSPACE_OFFSET = 'O',
  OPT_GUIDE_RTT = 'G',
  OPT_CPU_WAKE = 'W',
  OPT_LOOP = 'L',
  OPT_START_ON_ANSWER = 'A',
};

static const struct option haptic_long_options[] = {{"trajectory", required_argument, 0, OPT_TRAJECTORY},
                                                    {"loop", no_argument, 0, OPT_LOOP},
                                                    {"start-on-answer", no_argument, 0, OPT_START_ON_ANSWER},
                                                    {"tool", required_argument, 0, OPT_TOOL},
                                                    {"station", required_argument, 0, OPT_STATION},
                                                    {"rate", required_argument, 0, OPT_RATE},
                                                    {"max-force", required_argument, 0, OPT_MAX_FORCE},
                                                    {"max-stiffness", required_argument, 0, OPT_MAX_STIFFNESS},
                                                    {"wait-server", required_argument, 0, OPT_WAIT_SERVER},
                                                    {"duration", required_argument, 0, OPT_DURATION},
                                                    {"force-csv", required_argument, 0, OPT_FORCE_CSV},
                                                    {"rt-priority", required_argument, 0, OPT_RT_PRIORITY},
                                                    {"cpu-wake-latency", required_argument, 0, OPT_CPU_WAKE},
                                                    {"device", required_argument, 0, OPT_DEVICE},
                                                    {"guide-rtt", required_argument, 0, OPT_GUIDE_RTT},
                                                    {"device-index", required_argument, 0, OPT_DEVICE_INDEX},
                                                    {"workspace-scale", required_argument, 0, OPT_WORKSPACE_SCALE},
                                                    {"workspace-offset", required_argument, 0, OPT_WORKSPACE_OFFSET},
                                                    {0, 0, 0, 0}};

/* The options whose value is a non-negative number, and their names. */
static const char *number_option(int code) {
  switch (code) {
  case OPT_RATE:
    return "rate";
  case OPT_MAX_FORCE:
    return "max-force";
  case OPT_MAX_STIFFNESS:
    return "max-stiffness";
  case OPT_WAIT_SERVER:
    return "wait-server";
  case OPT_DURATION:
    return "duration";
  case OPT_DEVICE_INDEX:
    return "device-index";
  case OPT_WORKSPACE_SCALE:
    return "workspace-scale";
  case OPT_TOOL:
    return "tool";
  case OPT_GUIDE_RTT:
    return "guide-rtt";
  default:
    return NULL;
  }
}

static int workspace_offset(haptic_options_t *o, const char *arg) {
  double w[3];
  char tail = 0;
  if (sscanf(arg, "%lf,%lf,%lf%c", &w[0], &w[1], &w[2], &tail) != 3 || !isfinite(w[0]) || !isfinite(w[1]) ||
      !isfinite(w[2]) || fabs(w[0]) > 100 || fabs(w[1]) > 100 || fabs(w[2]) > 100) {
    fprintf(stderr, "viscera-haptic: --workspace-offset '%s': expected X,Y,Z in metres (|value| <= 100)\n", arg);
    return 2;
  }
  memcpy(o->dcfg.offset, w, sizeof w);
  return 0;
}

static int on_option(void *ctx, int code, const char *arg) {
  haptic_options_t *o = ctx;
  double v = 0;
  const char *number = number_option(code);
  if (number) {
    char *end = NULL;
    v = strtod(arg, &end);
    if (*end || !isfinite(v) || v < 0) {
      fprintf(stderr, "viscera-haptic: option --%s: '%s' is not a non-negative number\n", number, arg);
      return 2;
    }
  }
  switch (code) {
  case OPT_TRAJECTORY:
    o->trajectory = arg;
    return 0;
  case OPT_LOOP:
    o->dcfg.loop = 1;
    return 0;
  case OPT_START_ON_ANSWER:
    o->start_on_answer = 1;
    return 0;
  case OPT_TOOL:
    o->tool = (unsigned)v;
    return 0;
  case OPT_STATION:
    if (!station_name_valid(arg)) {
      fprintf(stderr, "viscera-haptic: --station '%s': 1..%d characters of A-Z a-z 0-9 _ . -\n", arg,
              VDDS_STATION_MAX - 1);
      return 2;
    }
    o->station = arg;
    return 0;
  case OPT_RATE:
    o->rate = v;
    return 0;
  case OPT_MAX_FORCE:
    o->max_force = v;
    return 0;
  case OPT_MAX_STIFFNESS:
    o->max_stiffness = v;
    return 0;
  case OPT_WAIT_SERVER:
    o->wait_server = v;
    return 0;
  case OPT_DURATION:
    o->duration = v;
    return 0;
  case OPT_GUIDE_RTT:
    if (v > 2) {
      fprintf(stderr, "viscera-haptic: --guide-rtt %s: at most 2 s\n", arg);
      return 2;
    }
    o->guide_rtt = v;
    return 0;
  case OPT_FORCE_CSV:
    o->force_csv = arg;
    return 0;
  case OPT_RT_PRIORITY:
    if (vrt_parse_priority(arg, &o->rt_priority)) {
      fprintf(stderr, "viscera-haptic: --rt-priority '%s' is not a SCHED_FIFO priority 1..99\n", arg);
      return 2;
    }
    return 0;
  case OPT_CPU_WAKE:
    return cpu_wake_option("viscera-haptic", arg, &o->cpu_wake_us);
  case OPT_DEVICE:
    o->device = arg;
    return 0;
  case OPT_DEVICE_INDEX:
    if (v != floor(v) || v > 15) {
      fprintf(stderr, "viscera-haptic: --device-index must be an integer 0..15\n");
      return 2;
    }
    o->dcfg.index = (int)v;
    return 0;
  case OPT_WORKSPACE_SCALE:
    if (!(v > 0) || v > 1000) {
      fprintf(stderr, "viscera-haptic: --workspace-scale must be > 0 and <= 1000\n");
      return 2;
    }
    o->dcfg.scale = v;
    return 0;
  case OPT_WORKSPACE_OFFSET:
    return workspace_offset(o, arg);
  }
  return 0; /* not reached: cli_parse passes only the codes above */
}

int haptic_options_parse(haptic_options_t *o, int argc, char **argv) {
  *o = (haptic_options_t){.device = "scripted",
                          .rate = 1000,
                          .max_force = 4,
                          .max_stiffness = 0,
                          .wait_server = 10,
                          .duration = -1,
                          .cpu_wake_us = -1};
  device_config_default(&o->dcfg);
  const cli_spec_t spec = {.program = "viscera-haptic",
                           .common = CLI_DOMAIN | CLI_DOMAIN_ENV | CLI_PARTITION | CLI_QUIET,
                           .shortopts = "j:Ln:s:d:p:r:m:K:w:t:f:R:D:I:S:O:qh",
                           .options = haptic_long_options,
                           .option = on_option,
                           .usage = haptic_usage};
  cli_common_t common = {0};
  int rc = cli_parse(&spec, argc, argv, &common, o);
  if (rc != CLI_RUN) return rc;
  o->domain = common.domain;
  o->partition = common.partition;
  o->quiet = common.quiet;
  if (!o->trajectory && strcmp(o->device, "scripted") == 0) {
    fprintf(stderr,
            "viscera-haptic: --trajectory FILE is required for the scripted device (or choose --device: "
            "this build has %s)\n",
            device_names());
    return 2;
  }
  if ((o->dcfg.loop || o->start_on_answer) && strcmp(o->device, "scripted") != 0) {
    fprintf(stderr, "viscera-haptic: --%s: only the scripted device plays a trajectory (--device is '%s')\n",
            o->dcfg.loop ? "loop" : "start-on-answer", o->device);
    return 2;
  }
  if (!(o->rate >= 10 && o->rate <= 10000) || !(o->max_force > 0)) {
    fprintf(stderr, "viscera-haptic: --rate must be 10..10000 Hz and --max-force > 0\n");
    return 2;
  }
  if (o->trajectory) { /* "palpate_kidney.traj" finds the installed one from any directory */
    data_path_resolve(o->trajectory, "assets/trajectories", o->trajectory_path, sizeof o->trajectory_path);
    o->trajectory = o->trajectory_path;
  }
  o->dcfg.trajectory = o->trajectory;
  o->dcfg.max_force = o->max_force;
  o->dcfg.max_stiffness = o->max_stiffness;
  return CLI_RUN;
}
