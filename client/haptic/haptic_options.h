/* SPDX-License-Identifier: Apache-2.0 */
/* haptic_options: the viscera-haptic command line (common options through
 * common/cli.h, the device and loop options here). */
#ifndef VISCERA_HAPTIC_OPTIONS_H
#define VISCERA_HAPTIC_OPTIONS_H

#include <stdio.h>

#include "data_path.h"
#include "device.h"

typedef struct haptic_options {
  const char *trajectory; /* --trajectory FILE (scripted device) */
  const char *partition;  /* --partition P, NULL: the default */
  const char *force_csv;  /* --force-csv FILE, or NULL */
  const char *device;     /* --device NAME (default "scripted") */
  const char *station;    /* --station NAME, or NULL */
  device_config_t dcfg;   /* --device-index, --workspace-scale/-offset, and the fields below once parsed */
  double guide_rtt;       /* --guide-rtt S: least round trip to a guiding peer (guide_force.h) */
  int domain, quiet, rt_priority;
  int cpu_wake_us;                     /* --cpu-wake-latency US (cpu_wake.h); -1: not asked */
  unsigned tool;                       /* --tool N */
  double rate;                         /* --rate HZ, loop rate */
  double max_force;                    /* --max-force N */
  double max_stiffness;                /* --max-stiffness K, N/m; 0 = no stated limit */
  double wait_server;                  /* --wait-server S */
  int start_on_answer;                 /* --start-on-answer: the path's clock starts at the server's first answer */
  double duration;                     /* --duration S; < 0: end of the trajectory + 0.5 s */
  char trajectory_path[DATA_PATH_MAX]; /* --trajectory found (data_path_resolve: installed ones by name) */
} haptic_options_t;

/* Defaults, $VISCERA_DOMAIN, then argv. Returns CLI_RUN (cli.h) to run, or
 * the exit code (0 after --help/--version, 2 after a message). */
int haptic_options_parse(haptic_options_t *o, int argc, char **argv);
void haptic_usage(FILE *f);

#endif
