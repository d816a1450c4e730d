/* SPDX-License-Identifier: Apache-2.0 */
/* viscera-report: per-trainee report from one or several session
 * recordings: HTML with embedded charts, CSV, and with several recordings a
 * comparison (novice against expert, docs/methods.md A Table 2, docs/methods.md B ch. 6).
 *
 * Bad input never stops the others: a file that is not a recording, or has
 * nothing to report, is named with the reason and skipped (exit 1); a
 * truncated or damaged one is reported from what is readable, with
 * warnings. */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "report_run.h"

static void usage(FILE *f) {
  fprintf(f,
          "usage: viscera-report [--out DIR] [--label NAME=REC.db ...] [--limits FILE] [--limit L ...] [REC.db ...]\n"
          "Writes a trainee report of session recordings (viscera-recorder files):\n"
          "  DIR/report.html  per recording: force over time with the ST/MPF/SFT lines, peak and\n"
          "                   mean palpation force, exploration (contact) time, time to first\n"
          "                   contact, operation time (per task when the recording has task\n"
          "                   events), time above each threshold, crossings, path length; with\n"
          "                   several recordings a comparison (table and one bar chart per\n"
          "                   measure). Self-contained: the charts are embedded.\n"
          "                   A lab recording (deploy/lab.sh, partitions lab/*) gives one section per\n"
          "                   seat and a lab summary table; every section names its seat and station\n"
          "                   and gives a verdict (PASS/FAIL per limit). Prints cleanly to PDF.\n"
          "  DIR/report.csv   one row per recording (per seat), with the verdict\n"
          "  DIR/*.png        the charts\n"
          "\n"
          "  -o, --out DIR           output directory (default: report), created if missing\n"
          "  -l, --label NAME=FILE   a recording with the name to show (e.g. expert=a.db)\n"
          "  -L, --limits FILE       the verdict's limits, one per line: MEASURE <= BOUND or\n"
          "                          MEASURE >= BOUND; MEASURE a report.csv column (peak_force_N,\n"
          "                          time_above_MPF_s, ...), BOUND a number or ST, MPF, SFT, 1.2*MPF\n"
          "                          (the session's own thresholds). Default: peak_force_N <= SFT,\n"
          "                          time_above_SFT_s <= 0, time_above_MPF_s <= 1\n"
          "      --limit L           one more limit (same form), replacing one on the same measure\n"
          "  -q, --quiet             no progress lines\n"
          "  -h, --help              this text\n"
          "      --version           print the version and exit\n"
          "Without --label a recording is named after its file (after its directory for\n"
          "a file named session.db, as deploy/session.sh writes). At most %d recordings.\n"
          "Exit status: 0 all reported, 1 some recording unusable (the others are\n"
          "still reported) or output not writable, 2 usage error.\n",
          MAX_RECORDINGS);
}

/* "dir/novice.db" -> "novice"; the generic name of deploy/session.sh,
 * "out/trainee-07/session.db", -> "trainee-07" (the directory says who). */
static void label_from_path(const char *path, char *out, size_t size) {
  const char *b = strrchr(path, '/');
  b = b ? b + 1 : path;
  size_t len = strlen(b);
  if (len > 3 && strcmp(b + len - 3, ".db") == 0) len -= 3;
  if (len == 7 && strncmp(b, "session", 7) == 0 && b > path + 1) {
    const char *end = b - 1, *d = end;
    while (d > path && d[-1] != '/') d--;
    bool dots = (end - d == 1 && d[0] == '.') || (end - d == 2 && d[0] == '.' && d[1] == '.');
    if (end > d && !dots) b = d, len = (size_t)(end - d);
  }
  if (len >= size) len = size - 1;
  memcpy(out, b, len);
  out[len] = 0;
  if (!out[0]) snprintf(out, size, "recording");
}

enum { OPT_OUT = 'o', OPT_LABEL = 'l', OPT_LIMITS = 'L', OPT_LIMIT = 1000 };

static int on_option(void *ctx, int code, const char *optarg) {
  report_options_t *o = ctx;
  switch (code) {
  case OPT_OUT:
    o->out = optarg;
    return 0;
  case OPT_LIMITS:
  case OPT_LIMIT: {
    verr_t err = {{0}};
    if ((code == OPT_LIMITS ? rep_limits_load(&o->limits, optarg, &err) : rep_limits_add(&o->limits, optarg, &err)) <
        0) {
      fprintf(stderr, "report: %s\n", err.msg);
      return 2;
    }
    return 0;
  }
  case OPT_LABEL: {
    const char *eq = strchr(optarg, '=');
    if (!eq || eq == optarg || !eq[1]) {
      fprintf(stderr, "report: --label '%s': expected NAME=FILE.db\n", optarg);
      return 2;
    }
    if (o->nin >= MAX_RECORDINGS) {
      fprintf(stderr, "report: at most %d recordings\n", MAX_RECORDINGS);
      return 2;
    }
    input_t *in = &o->in[o->nin++];
    size_t len = (size_t)(eq - optarg);
    if (len >= sizeof in->label) len = sizeof in->label - 1;
    memcpy(in->label, optarg, len);
    in->label[len] = 0;
    in->path = eq + 1;
    return 0;
  }
  }
  return 0; /* not reached: cli_parse passes only the codes above */
}

int main(int argc, char **argv) {
  static const struct option longopts[] = {
      {"out", required_argument, 0, OPT_OUT},
      {"label", required_argument, 0, OPT_LABEL},
      {"limits", required_argument, 0, OPT_LIMITS},
      {"limit", required_argument, 0, OPT_LIMIT},
      {0, 0, 0, 0},
  };
  const cli_spec_t spec = {.program = "viscera-report",
                           .tag = "report",
                           .common = CLI_QUIET,
                           .shortopts = "o:l:L:qh",
                           .options = longopts,
                           .option = on_option,
                           .usage = usage};
  static report_options_t o = {.out = "report"};
  rep_limits_default(&o.limits);
  cli_common_t common = {0};
  int rc = cli_parse(&spec, argc, argv, &common, &o);
  if (rc != CLI_RUN) return rc;
  o.quiet = common.quiet;
  for (int i = optind; i < argc; i++) {
    if (o.nin >= MAX_RECORDINGS) {
      fprintf(stderr, "report: at most %d recordings\n", MAX_RECORDINGS);
      return 2;
    }
    o.in[o.nin].path = argv[i];
    label_from_path(argv[i], o.in[o.nin].label, sizeof o.in[o.nin].label);
    o.nin++;
  }
  if (!o.nin) {
    fprintf(stderr, "report: no recording given\n");
    usage(stderr);
    return 2;
  }
  /* Sections, chart legends and CSV rows are told apart by the name alone:
   * two recordings of one name would read as one trainee. */
  for (int i = 1; i < o.nin; i++)
    for (int j = 0; j < i; j++)
      if (!strcmp(o.in[i].label, o.in[j].label)) {
        fprintf(stderr, "report: two recordings are named '%s' (%s and %s): give each its own --label NAME=FILE.db\n",
                o.in[i].label, o.in[j].path, o.in[i].path);
        return 2;
      }
  return report_run(&o);
}
