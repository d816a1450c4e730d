/* SPDX-License-Identifier: Apache-2.0 */
/* viscera-recorder: records every topic of a session into one SQLite file.
 *
 * Generic by design: it compiles in no product type. Topics and their types
 * are discovered at run time (see session.h), so topics added to the
 * product later are recorded without rebuilding the recorder. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "cli.h"
#include "dds/vdds.h"
#include "recorder_run.h"

static void usage(FILE *f) {
  fprintf(f, "usage: viscera-recorder --out FILE.db [options]\n"
             "Records every topic published in a DDS partition into one SQLite file\n"
             "(raw CDR plus type descriptors; read it with viscera-recinfo).\n"
             "\n"
             "  -o, --out FILE.db     recording to create (required)\n"
             "  -f, --force           overwrite FILE.db if it exists\n"
             "  -d, --domain N        DDS domain id 0..230 (default: $VISCERA_DOMAIN, else 0)\n" CLI_HELP_INSECURE
             "  -p, --partition P     partition to record; fnmatch-style patterns such as\n"
             "                        'lab1/*' record several sessions (default: viscera/local)\n"
             "  -t, --duration S      stop after S seconds (default: until SIGINT/SIGTERM)\n"
             "  -s, --scene NAME      scene name stored in the session metadata\n"
             "      --depth N         reader history per instance, samples (default 1000):\n"
             "                        how long a stall of the recorder is absorbed\n"
             "  -q, --quiet           no progress line\n"
             "  -h, --help            this text\n"
             "      --version         print the version and exit\n"
             "\n"
             "Progress goes to stderr once per second. SIGINT/SIGTERM finish the current\n"
             "batch, write the end time and close the file; a second signal kills at once\n"
             "(the file stays readable, the last batch of at most 200 ms is lost).\n"
             "A full disk (or file-size limit) stops the recording cleanly: the file keeps\n"
             "every committed batch and stays readable, the recorder exits with status 1.\n"
             "Exit status: 0 done, 1 runtime error (disk full included), 2 usage error.\n"
             "DDS configuration comes from CYCLONEDDS_URI.\n");
}

enum { OPT_OUT = 'o', OPT_FORCE = 'f', OPT_DURATION = 't', OPT_SCENE = 's', OPT_DEPTH = 1000 };

static int on_option(void *ctx, int code, const char *arg) {
  recorder_options_t *ro = ctx;
  char *end = NULL;
  switch (code) {
  case OPT_OUT:
    ro->session.out = arg;
    return 0;
  case OPT_FORCE:
    ro->session.force = true;
    return 0;
  case OPT_DURATION:
    ro->duration = strtod(arg, &end);
    if (!*arg || *end || !isfinite(ro->duration) || ro->duration <= 0 || ro->duration > 1e7) {
      fprintf(stderr, "recorder: --duration '%s': expected seconds > 0\n", arg);
      return 2;
    }
    return 0;
  case OPT_SCENE:
    ro->session.scene = arg;
    return 0;
  case OPT_DEPTH: {
    long d = strtol(arg, &end, 10);
    if (!*arg || *end || d < 1 || d > 1000000) {
      fprintf(stderr, "recorder: --depth '%s': expected 1..1000000\n", arg);
      return 2;
    }
    ro->session.depth = (int32_t)d;
    return 0;
  }
  }
  return 0; /* not reached: cli_parse passes only the codes above */
}

int main(int argc, char **argv) {
  vdds_set_role("recorder"); /* announced in the participant USER_DATA */
  static const struct option longopts[] = {
      {"out", required_argument, 0, OPT_OUT},           {"force", no_argument, 0, OPT_FORCE},
      {"duration", required_argument, 0, OPT_DURATION}, {"scene", required_argument, 0, OPT_SCENE},
      {"depth", required_argument, 0, OPT_DEPTH},       {0, 0, 0, 0},
  };
  const cli_spec_t spec = {.program = "viscera-recorder",
                           .tag = "recorder",
                           .common = CLI_DOMAIN | CLI_DOMAIN_ENV | CLI_PARTITION | CLI_QUIET,
                           .shortopts = "o:fd:p:t:s:qh",
                           .options = longopts,
                           .option = on_option,
                           .usage = usage,
                           .domain_error = "--domain '%s': expected an integer 0..230",
                           .partition_error = "--partition: empty pattern"};
  recorder_options_t ro = {.session = {.partition = "viscera/local", .log = stderr}};
  cli_common_t common = {.partition = "viscera/local"};
  int rc = cli_parse(&spec, argc, argv, &common, &ro);
  if (rc != CLI_RUN) return rc;
  ro.session.domain = common.domain;
  ro.session.partition = common.partition;
  ro.quiet = common.quiet;
  if (optind < argc) {
    fprintf(stderr, "recorder: unexpected argument '%s'\n", argv[optind]);
    usage(stderr);
    return 2;
  }
  if (!ro.session.out) {
    fprintf(stderr, "recorder: --out FILE.db is required\n");
    usage(stderr);
    return 2;
  }
  return recorder_run(&ro);
}
