/* SPDX-License-Identifier: Apache-2.0 */
/* viscera-control: sends one instructor command (SessionControl) to a seat's
 * server and waits for the server's answer (a SessionEvent saying it was
 * applied or refused), so a script or an instructor sees the outcome.
 *
 * Only identities allowed to publish SessionControl in the seat's partition
 * can use it when DDS Security is on (deploy/pki.sh): for anyone else the
 * writer cannot be created and the command says so. */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "station.h"
#include "cli.h"
#include "control_run.h"
#include "dds/vdds.h"
#include "viscera.h"
#include "vtime.h"

static void usage(FILE *f) {
  fprintf(f, "usage: viscera-control [options] COMMAND\n"
             "  pause                 freeze the seat's physics and measures\n"
             "  resume                continue\n"
             "  thresholds T ST MPF SFT   new palpation thresholds (N) for tool T (0 = not set)\n"
             "  reset                 restart the scene from rest (organs, tools, measures, tasks)\n"
             "  material O K C H M    organ O's stiffness K (N/m), damping C (N s/m), home stiffness H\n"
             "                        (N/m), mass M (kg); -1 keeps a value; the organ restarts from rest\n"
             "  assign T STATION|*    only STATION's haptic client drives tool T from now on (* = any\n"
             "                        station); ends any guiding of T\n"
             "  guide T STATION [A [K]]  couple STATION's device to tool T ('guiding hand'): the tool\n"
             "                        goes to A * guide + (1 - A) * owner, A in 0..1 (default 0.5);\n"
             "                        coupling stiffness K N/m between the two devices (default: the\n"
             "                        server's, 200 or the tool's stiffness if lower)\n"
             "  takeover T STATION    guide with authority 1: STATION drives T, the owner's hand is led\n"
             "  release T             end guiding: tool T is its owner's again\n"
             "  (STATION: a haptic client's --station name, 1..31 of A-Z a-z 0-9 _ . -)\n"
             "  start-task NAME|INDEX start (or restart) a task now, by its scene name or index;\n"
             "                        a restart replaces the earlier run (clock from now)\n"
             "  --domain N            DDS domain id (default: $VISCERA_DOMAIN or 0)\n" CLI_HELP_INSECURE
             "  --partition P         the seat's partition (default: " VDDS_DEFAULT_PARTITION ")\n"
             "  --station ID          this instructor console's number (SessionControl source_id, default\n"
             "                        1); not a haptic client's station name\n"
             "  --text TEXT           who/why, kept in the recording\n"
             "  --wait S              wait up to S s for the server's answer (default 5)\n"
             "  --help                this text\n"
             "  --version             print the version and exit\n"
             "Exit status: 0 applied, 1 refused or no answer, 2 usage or DDS error.\n");
}

static int parse_double(const char *s, double *out) {
  char *end;
  *out = strtod(s, &end);
  return end != s && *end == 0 && isfinite(*out) ? 0 : -1;
}

/* assign / guide / takeover / release (idl CONTROL_ASSIGN_TOOL, CONTROL_GUIDE):
 * the station travels in the command's text, so --text cannot go with them.
 * argv[0] is the verb. Returns 0, or -1 after saying what is wrong. */
/* "INDEX V1 .. Vn" of the material and thresholds verbs: an index 0..1000
 * then n numbers; -1 after saying which argument is wrong. */
static int parse_index_values(const char *verb, const char *index_what, const char *value_what, char **args, int n,
                              int32_t *index, double *values) {
  char *end;
  long i = strtol(args[0], &end, 10);
  if (!args[0][0] || *end || i < 0 || i > 1000) {
    fprintf(stderr, "viscera-control: %s: not %s: '%s'\n", verb, index_what, args[0]);
    return -1;
  }
  *index = (int32_t)i;
  for (int k = 0; k < n; k++)
    if (parse_double(args[1 + k], &values[k])) {
      fprintf(stderr, "viscera-control: %s: not %s: '%s'\n", verb, value_what, args[1 + k]);
      return -1;
    }
  return 0;
}

static int parse_role(const char *verb, int argc, char **argv, int has_text, viscera_SessionControl *cmd) {
  int release = strcmp(verb, "release") == 0, guide = strcmp(verb, "guide") == 0;
  int want_min = release ? 2 : 3, want_max = release ? 2 : guide ? 5 : 3;
  if (argc < want_min || argc > want_max) {
    fprintf(stderr, "viscera-control: %s: usage: %s\n", verb,
            release                       ? "release TOOL"
            : guide                       ? "guide TOOL STATION [AUTHORITY [K]]"
            : strcmp(verb, "assign") == 0 ? "assign TOOL STATION|*"
                                          : "takeover TOOL STATION");
    return -1;
  }
  if (has_text) {
    fprintf(stderr, "viscera-control: %s: --text cannot be used (the station goes in the command's text)\n", verb);
    return -1;
  }
  char *end;
  long tool = strtol(argv[1], &end, 10);
  if (*argv[1] == 0 || *end || tool < 0 || tool > 1000) {
    fprintf(stderr, "viscera-control: %s: not a tool index: '%s'\n", verb, argv[1]);
    return -1;
  }
  cmd->tool_id = (int32_t)tool;
  cmd->kind = strcmp(verb, "assign") == 0 ? viscera_CONTROL_ASSIGN_TOOL : viscera_CONTROL_GUIDE;
  if (release) return 0; /* GUIDE with station "": guiding ends */
  const char *station = argv[2];
  int any = cmd->kind == viscera_CONTROL_ASSIGN_TOOL && strcmp(station, "*") == 0;
  if (!any && !station_name_valid(station)) {
    fprintf(stderr, "viscera-control: %s: station '%s' is not 1..%d characters of A-Z a-z 0-9 _ . -%s\n", verb, station,
            VDDS_STATION_MAX - 1, cmd->kind == viscera_CONTROL_ASSIGN_TOOL ? " (or * for any station)" : "");
    return -1;
  }
  snprintf(cmd->text, sizeof cmd->text, "%s", station);
  if (cmd->kind == viscera_CONTROL_ASSIGN_TOOL) return 0;
  cmd->values[0] = guide ? 0.5 : 1.0;
  if (argc >= 4 && (parse_double(argv[3], &cmd->values[0]) || cmd->values[0] < 0 || cmd->values[0] > 1)) {
    fprintf(stderr, "viscera-control: guide: authority '%s' is not a number in 0..1\n", argv[3]);
    return -1;
  }
  if (argc >= 5 && parse_double(argv[4], &cmd->values[1])) {
    fprintf(stderr, "viscera-control: guide: coupling stiffness '%s' is not a number (N/m)\n", argv[4]);
    return -1;
  }
  return 0;
}

/* The COMMAND words (argv[0] the verb) into cmd. Returns 0, or 2 after
 * saying what is wrong. */
static int parse_command(int argc, char **argv, int has_text, viscera_SessionControl *cmd) {
  const char *verb = argc > 0 ? argv[0] : NULL;
  if (verb && strcmp(verb, "pause") == 0 && argc == 1) {
    cmd->kind = viscera_CONTROL_PAUSE;
  } else if (verb && strcmp(verb, "resume") == 0 && argc == 1) {
    cmd->kind = viscera_CONTROL_RESUME;
  } else if (verb && strcmp(verb, "reset") == 0 && argc == 1) {
    cmd->kind = viscera_CONTROL_RESET;
  } else if (verb && strcmp(verb, "material") == 0 && argc == 6) {
    cmd->kind = viscera_CONTROL_SET_MATERIAL;
    if (parse_index_values("material", "an organ index", "a number", argv + 1, 4, &cmd->organ_id, cmd->values))
      return 2;
  } else if (verb && strcmp(verb, "thresholds") == 0 && argc == 5) {
    cmd->kind = viscera_CONTROL_SET_THRESHOLDS;
    if (parse_index_values("thresholds", "a tool index", "a force in N", argv + 1, 3, &cmd->tool_id, cmd->values))
      return 2;
  } else if (verb && (strcmp(verb, "assign") == 0 || strcmp(verb, "guide") == 0 || strcmp(verb, "takeover") == 0 ||
                      strcmp(verb, "release") == 0)) {
    if (parse_role(verb, argc, argv, has_text, cmd)) return 2;
  } else if (verb && strcmp(verb, "start-task") == 0 && argc == 2) {
    /* A name goes in `text` (so --text is not used); all digits is an index. */
    cmd->kind = viscera_CONTROL_START_TASK;
    const char *arg = argv[1];
    if (*arg && strspn(arg, "0123456789") == strlen(arg)) {
      if (strlen(arg) > 4) {
        fprintf(stderr, "viscera-control: start-task: task index too large: '%s'\n", arg);
        return 2;
      }
      cmd->text[0] = 0;
      cmd->values[0] = atof(arg);
    } else {
      if (!*arg || strlen(arg) >= sizeof cmd->text) {
        fprintf(stderr, "viscera-control: start-task: not a task name: '%s'\n", arg);
        return 2;
      }
      snprintf(cmd->text, sizeof cmd->text, "%s", arg);
    }
  } else {
    usage(stderr);
    return 2;
  }

  return 0;
}

enum { OPT_STATION = 's', OPT_TEXT = 't', OPT_WAIT = 'w' };

static int on_option(void *ctx, int code, const char *arg) {
  control_options_t *o = ctx;
  switch (code) {
  case OPT_STATION: {
    char *end;
    unsigned long station = strtoul(arg, &end, 10);
    if (*arg == 0 || *end || station > 1000000) {
      fprintf(stderr, "viscera-control: --station: not a station id: '%s'\n", arg);
      return 2;
    }
    o->cmd.source_id = (uint32_t)station;
    return 0;
  }
  case OPT_TEXT:
    snprintf(o->cmd.text, sizeof o->cmd.text, "%s", arg);
    o->has_text = *arg != 0;
    return 0;
  case OPT_WAIT:
    if (parse_double(arg, &o->wait_s) || o->wait_s < 0) {
      fprintf(stderr, "viscera-control: --wait: not a duration: '%s'\n", arg);
      return 2;
    }
    return 0;
  }
  return 0; /* not reached: cli_parse passes only the codes above */
}

int main(int argc, char **argv) {
  vdds_set_role("control"); /* announced in the participant USER_DATA */
  static const struct option opts[] = {{"station", required_argument, 0, OPT_STATION},
                                       {"text", required_argument, 0, OPT_TEXT},
                                       {"wait", required_argument, 0, OPT_WAIT},
                                       {0, 0, 0, 0}};
  const cli_spec_t spec = {.program = "viscera-control",
                           .common = CLI_DOMAIN | CLI_DOMAIN_ENV | CLI_PARTITION,
                           .shortopts = "+h", /* stop at the command, so "-1" values are not options */
                           .options = opts,
                           .option = on_option,
                           .usage = usage,
                           .domain_error = "--domain: not a domain id: '%s'"};
  control_options_t o = {.wait_s = 5};
  memset(&o.cmd, 0, sizeof o.cmd);
  o.cmd.source_id = 1;
  cli_common_t common = {0};
  int rc = cli_parse(&spec, argc, argv, &common, &o);
  if (rc != CLI_RUN) return rc;
  o.domain = common.domain;
  o.partition = common.partition;
  o.cmd.seq = vtime_mono_ns(); /* increasing across invocations of one station */
  o.cmd.tool_id = -1;
  o.cmd.organ_id = -1;
  if (parse_command(argc - optind, argv + optind, o.has_text, &o.cmd)) return 2;
  return control_run(&o);
}
