/* SPDX-License-Identifier: Apache-2.0 */
/* viscera-replay: republishes a session recording (recording.h) over DDS,
 * with no compiled-in type.
 *
 * For every recorded topic the type descriptor is rebuilt from the stored
 * fields, the topic created with it and a writer with the recorded QoS
 * (replay_topic.h). Samples are then published in recorded (insertion)
 * order at their original pace (source timestamps, scaled by --speed;
 * replay_run.h), each checked against its type and forwarded with its
 * original source timestamp and status (replay_write.h).
 *
 * Pause: SIGUSR1 toggles pause/resume, --pause-at S pauses once when the
 * replay reaches recording time S. While paused nothing is written; at
 * resume the rest of the schedule is shifted by the paused time
 * (replay_pause.h), so the samples keep their original spacing.
 *
 * usage: viscera-replay FILE.db [--domain N] [--partition P] [--speed X]
 *                       [--seek S] [--pause-at S] [--loop] [--quiet] */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>

#include "cli.h"
#include "dds/vdds_ident.h"
#include "replay_run.h"

static void usage(FILE *f) {
  fprintf(f, "usage: viscera-replay FILE.db [--domain N] [--partition P] [--speed X] [--seek S] [--pause-at S]\n"
             "                      [--loop] [--quiet]\n"
             "  --domain N      DDS domain to publish in (default: the recorded one)\n" CLI_HELP_INSECURE
             "  --partition P   partition to publish in (default: the recorded one, if not a pattern)\n"
             "  --speed X       playback speed factor, > 0 and at most 1e6 (default 1)\n"
             "  --seek S        skip the first S seconds (transient-local state is still sent)\n"
             "  --pause-at S    pause when the replay reaches recording time S seconds (once)\n"
             "  --loop          start over at the end until interrupted\n"
             "  --quiet         no progress lines\n"
             "  --help          this text\n"
             "  --version       print the version and exit\n"
             "SIGUSR1 toggles pause/resume; after a resume the original timing goes on\n"
             "(the schedule is shifted by the paused time, no burst of missed samples).\n"
             "Exit status: 0 done, 1 unreadable or damaged recording (what was readable was replayed), DDS error\n"
             "or usage error.\n");
}

enum { OPT_SPEED = 's', OPT_SEEK = 'k', OPT_LOOP = 'l', OPT_PAUSE_AT = 'P' };

/* A number in lo..hi (lo itself allowed only when `lo_ok`), or -1 after the
 * message "replay: --NAME 'ARG': expected WHAT". */
static int number(const char *name, const char *arg, double lo, int lo_ok, double hi, const char *what, double *out) {
  char *end;
  *out = strtod(arg, &end);
  if (*end || end == arg || !(*out > lo || (lo_ok && *out == lo)) || *out > hi) {
    fprintf(stderr, "replay: --%s '%s': expected %s\n", name, arg, what);
    return 1;
  }
  return 0;
}

static int on_option(void *ctx, int code, const char *arg) {
  replay_options_t *r = ctx;
  switch (code) {
  case OPT_SPEED:
    return number("speed", arg, 0.0, 0, 1e6, "a number > 0 and at most 1e6", &r->speed);
  case OPT_PAUSE_AT:
    return number("pause-at", arg, 0.0, 1, 1e8, "seconds, 0 to 1e8", &r->pause_at);
  case OPT_SEEK:
    return number("seek", arg, 0.0, 1, 1e8, "seconds, 0 to 1e8", &r->seek);
  case OPT_LOOP:
    r->loop = true;
    return 0;
  }
  return 0; /* not reached: cli_parse passes only the codes above */
}

/* Returns CLI_RUN, or the exit code (0 after --help/--version, 1 on a
 * usage error, as replay always had). */
static int parse_args(replay_options_t *r, int argc, char **argv) {
  static const struct option opts[] = {{"speed", required_argument, NULL, OPT_SPEED},
                                       {"seek", required_argument, NULL, OPT_SEEK},
                                       {"loop", no_argument, NULL, OPT_LOOP},
                                       {"pause-at", required_argument, NULL, OPT_PAUSE_AT},
                                       {NULL, 0, NULL, 0}};
  const cli_spec_t spec = {.program = "viscera-replay",
                           .tag = "replay",
                           .common = CLI_DOMAIN | CLI_PARTITION | CLI_QUIET,
                           .options = opts,
                           .option = on_option,
                           .shortopts = "h",
                           .usage = usage,
                           .domain_error = "--domain '%s': expected an integer 0..230",
                           .partition_error = "--partition: empty or too long",
                           .partition_max = sizeof r->partition,
                           .usage_status = 1};
  r->speed = 1.0;
  r->pause_at = -1.0;
  cli_common_t common = {.domain = -1}; /* -1: the recorded one */
  int rc = cli_parse(&spec, argc, argv, &common, r);
  if (rc != CLI_RUN) return rc;
  r->domain = common.domain;
  if (common.partition) snprintf(r->partition, sizeof r->partition, "%s", common.partition);
  r->quiet = common.quiet;
  if (optind != argc - 1) {
    usage(stderr);
    return 1;
  }
  r->path = argv[optind];
  return CLI_RUN;
}

int main(int argc, char **argv) {
  vdds_set_role("replay"); /* announced in the participant USER_DATA */
  replay_options_t o = {0};
  int rc = parse_args(&o, argc, argv);
  if (rc != CLI_RUN) return rc;
  return replay_run(&o);
}
