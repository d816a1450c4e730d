/* SPDX-License-Identifier: Apache-2.0 */
/* viscera-resim: deterministic re-simulation of a recorded session.
 *
 * Feeds the inputs the server applied (AppliedInput; in older recordings
 * the ToolCommands scheduled from the recorded ContactFeedback,
 * resim_schedule.h) into a fresh runtime of the recorded scene and compares every recorded mesh frame
 * with the re-simulated surface (resim_run.h). Exit 0 when every organ's
 * largest per-coordinate error is within the tolerance, 1 beyond it, 2 on
 * a usage error, an unreadable recording or a scene that is not the
 * recorded one. No DDS: runs anywhere the recording is. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "cli.h"
#include "resim/resim_app.h"

static void usage(FILE *f) {
  fprintf(f, "usage: viscera-resim REC.db [options]\n"
             "  --scene FILE      re-simulate with this scene file instead of the recording's own (names what\n"
             "                    differs; must match the recording's SceneInfo)\n"
             "  --mesh-dir DIR    look here, by file name, for a recorded mesh that is not where the server\n"
             "                    read it (taken only with the recorded sha256)\n"
             "  --tolerance M     largest per-coordinate error allowed, m (default: quant_step/2 + 5e-8)\n"
             "  --csv FILE        one line per compared frame: step,sim_time_s,organ,kind,max_err_m,rms_err_m,exact\n"
             "  --partition P     the session of partition P (a lab's recording holds every seat's session,\n"
             "                    e.g. lab/seat03); needed when the recording holds more than one\n"
             "  --run N           the session's Nth run of its server (1 = the first; default the last): a\n"
             "                    server killed and restarted while the recorder ran leaves several\n"
             "  --quiet           no progress lines\n"
             "  --help            this text\n"
             "  --version         print the version and exit\n"
             "Re-applies every input the server applied (AppliedInput: tool commands, releases, controls) in a\n"
             "fresh server runtime and compares every recorded MeshState/MeshDelta frame, ObjectState and\n"
             "interaction event.\nExit status: 0 within tolerance, 1 beyond, 2 on an error or a usage error.\n");
}

enum { OPT_SCENE = 's', OPT_TOLERANCE = 't', OPT_CSV = 'c', OPT_MESH_DIR = 'm', OPT_RUN = 'r' };

static int on_option(void *ctx, int code, const char *arg) {
  resim_options_t *o = ctx;
  char *end = NULL;
  switch (code) {
  case OPT_SCENE:
    o->scene_path = arg;
    return 0;
  case OPT_CSV:
    o->csv_path = arg;
    return 0;
  case OPT_MESH_DIR:
    o->mesh_dir = arg;
    return 0;
  case OPT_TOLERANCE:
    o->tolerance = strtod(arg, &end);
    if (!end || *end || !(o->tolerance >= 0) || !isfinite(o->tolerance)) {
      fprintf(stderr, "viscera-resim: --tolerance '%s' is not a length in m >= 0\n", arg);
      return 2;
    }
    return 0;
  case OPT_RUN: {
    long v = strtol(arg, &end, 10);
    if (!end || *end || end == arg || v < 1 || v > 1000000) {
      fprintf(stderr, "viscera-resim: --run '%s' is not a run number 1, 2, ...\n", arg);
      return 2;
    }
    o->run = (size_t)v;
    return 0;
  }
  }
  return 0; /* not reached: cli_parse passes only the codes above */
}

int main(int argc, char **argv) {
  static const struct option lo[] = {
      {"scene", required_argument, 0, OPT_SCENE}, {"tolerance", required_argument, 0, OPT_TOLERANCE},
      {"csv", required_argument, 0, OPT_CSV},     {"mesh-dir", required_argument, 0, OPT_MESH_DIR},
      {"run", required_argument, 0, OPT_RUN},     {0, 0, 0, 0}};
  const cli_spec_t spec = {.program = "viscera-resim",
                           .common = CLI_QUIET | CLI_PARTITION,
                           .partition_error = "--partition needs 1..255 characters",
                           .partition_max = 256,
                           .shortopts = "s:t:c:m:r:qh",
                           .options = lo,
                           .option = on_option,
                           .usage = usage};
  resim_options_t o = {.tolerance = -1};
  cli_common_t common = {0};
  int rc = cli_parse(&spec, argc, argv, &common, &o);
  if (rc != CLI_RUN) return rc;
  o.quiet = common.quiet;
  o.partition = common.partition;
  if (optind != argc - 1) {
    fprintf(stderr, "viscera-resim: expected one recording REC.db\n");
    usage(stderr);
    return 2;
  }
  o.rec_path = argv[optind];
  return resim_app_run(&o);
}
