/* viscera-report: per-trainee report from one or several session
 * recordings: HTML with embedded charts, CSV, and with several recordings a
 * comparison (novice against expert, seed 000 Table 2, seed 002 ch. 6).
 *
 * Bad input never stops the others: a file that is not a recording, or has
 * nothing to report, is named with the reason and skipped (exit 1); a
 * truncated or damaged one is reported from what is readable, with
 * warnings. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "charts.h"
#include "measure_table.h"
#include "plot/plot_cleanup.h"
#include "recording_data.h"
#include "report_write.h"

#define MAX_RECORDINGS 16

static void usage(FILE *f) {
  fprintf(f,
          "usage: viscera-report [--out DIR] [--label NAME=REC.db ...] [REC.db ...]\n"
          "Writes a trainee report of session recordings (viscera-recorder files):\n"
          "  DIR/report.html  per recording: force over time with the ST/MPF/SFT lines, peak and\n"
          "                   mean palpation force, exploration (contact) time, time to first\n"
          "                   contact, operation time (per task when the recording has task\n"
          "                   events), time above each threshold, crossings, path length; with\n"
          "                   several recordings a comparison (table and one bar chart per\n"
          "                   measure). Self-contained: the charts are embedded.\n"
          "  DIR/report.csv   one row per recording\n"
          "  DIR/*.png        the charts\n"
          "\n"
          "  -o, --out DIR           output directory (default: report), created if missing\n"
          "  -l, --label NAME=FILE   a recording with the name to show (e.g. expert=a.db)\n"
          "  -q, --quiet             no progress lines\n"
          "  -h, --help              this text\n"
          "Without --label a recording is named after its file (after its directory for\n"
          "a file named session.db, as deploy/session.sh writes). At most %d recordings.\n"
          "Exit status: 0 all reported, 1 some recording unusable (the others are\n"
          "still reported) or output not writable, 2 usage error.\n",
          MAX_RECORDINGS);
}

typedef struct input {
  const char *path;
  char label[64];
} input_t;

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

/* Label as a file-name part: [A-Za-z0-9_-], anything else becomes '_'. */
static void file_part(const char *label, char *out, size_t size) {
  size_t i = 0;
  for (; label[i] && i + 1 < size; i++) {
    char ch = label[i];
    out[i] = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '-' ? ch : '_';
  }
  out[i] = 0;
}

int main(int argc, char **argv) {
  const char *out = "report";
  bool quiet = false;
  input_t in[MAX_RECORDINGS];
  int nin = 0;
  static const struct option longopts[] = {
      {"out", required_argument, 0, 'o'},
      {"label", required_argument, 0, 'l'},
      {"quiet", no_argument, 0, 'q'},
      {"help", no_argument, 0, 'h'},
      {0, 0, 0, 0},
  };
  int c;
  while ((c = getopt_long(argc, argv, "o:l:qh", longopts, NULL)) != -1) {
    switch (c) {
    case 'o':
      out = optarg;
      break;
    case 'l': {
      const char *eq = strchr(optarg, '=');
      if (!eq || eq == optarg || !eq[1]) {
        fprintf(stderr, "report: --label '%s': expected NAME=FILE.db\n", optarg);
        return 2;
      }
      if (nin >= MAX_RECORDINGS) {
        fprintf(stderr, "report: at most %d recordings\n", MAX_RECORDINGS);
        return 2;
      }
      size_t len = (size_t)(eq - optarg);
      if (len >= sizeof in[0].label) len = sizeof in[0].label - 1;
      memcpy(in[nin].label, optarg, len);
      in[nin].label[len] = 0;
      in[nin++].path = eq + 1;
      break;
    }
    case 'q':
      quiet = true;
      break;
    case 'h':
      usage(stdout);
      return 0;
    default:
      usage(stderr);
      return 2;
    }
  }
  for (int i = optind; i < argc; i++) {
    if (nin >= MAX_RECORDINGS) {
      fprintf(stderr, "report: at most %d recordings\n", MAX_RECORDINGS);
      return 2;
    }
    in[nin].path = argv[i];
    label_from_path(argv[i], in[nin].label, sizeof in[nin].label);
    nin++;
  }
  if (!nin) {
    fprintf(stderr, "report: no recording given\n");
    usage(stderr);
    return 2;
  }
  if (mkdir(out, 0755) != 0 && errno != EEXIST) {
    fprintf(stderr, "report: cannot create output directory %s: %s\n", out, strerror(errno));
    return 1;
  }

  rep_recording_t *recs = calloc((size_t)nin, sizeof *recs);
  const rep_recording_t *ok[MAX_RECORDINGS];
  if (!recs) {
    fprintf(stderr, "report: out of memory\n");
    return 1;
  }
  int nok = 0, status = 0;
  for (int i = 0; i < nin; i++) {
    if (!quiet) fprintf(stderr, "report: reading %s (%s)\n", in[i].path, in[i].label);
    verr_t err = {{0}};
    rep_recording_t *r = &recs[i];
    if (rep_recording_load(r, in[i].path, in[i].label, &err) < 0) {
      fprintf(stderr, "report: error: %s; skipped\n", err.msg);
      rep_recording_free(r);
      status = 1;
      continue;
    }
    /* Warnings always go to stderr: they say the figures are partial. */
    const char *w = r->warnings;
    while (*w) {
      const char *nl = strchr(w, '\n');
      int len = nl ? (int)(nl - w) : (int)strlen(w);
      fprintf(stderr, "report: warning: %s: %.*s\n", in[i].path, len, w);
      w += len + (nl ? 1 : 0);
    }
    if (!quiet) {
      size_t nf = 0, nc = 0;
      for (int t = 0; t < r->ntools; t++) nf += r->tools[t].nforce, nc += r->tools[t].ncmd;
      fprintf(stderr,
              "report: %s: %zu force samples, %zu commands, %zu events; peak %.2f N, contact %.2f s, above MPF "
              "%.2f s, path %.1f cm\n",
              r->label, nf, nc, r->nevents, r->sum.peak_force, r->sum.contact_time, r->sum.time_above[THR_MPF],
              r->sum.path_length * 100);
    }
    ok[nok++] = r;
  }
  if (!nok) {
    fprintf(stderr, "report: no usable recording, no report written\n");
    free(recs);
    return 1;
  }

  /* Charts: file names from the labels, numbered so equal labels differ. */
  size_t plen = strlen(out) + 160;
  char *force_png[MAX_RECORDINGS] = {0}, *compare_png[REP_NMEASURES] = {0};
  for (int i = 0; i < nok; i++) {
    char part[64];
    file_part(ok[i]->label, part, sizeof part);
    force_png[i] = malloc(plen);
    if (!force_png[i]) continue;
    snprintf(force_png[i], plen, "%s/force_%02d_%s.png", out, i + 1, part);
    verr_t err = {{0}};
    if (rep_chart_force(ok[i], force_png[i], &err) < 0) {
      fprintf(stderr, "report: warning: %s: no force chart: %s\n", ok[i]->label, err.msg);
      free(force_png[i]);
      force_png[i] = NULL;
    }
  }
  if (nok >= 2)
    for (int m = 0; m < REP_NMEASURES; m++) {
      compare_png[m] = malloc(plen);
      if (!compare_png[m]) continue;
      snprintf(compare_png[m], plen, "%s/compare_%02d_%s.png", out, m + 1, rep_measure(m)->key);
      verr_t err = {{0}};
      if (rep_chart_compare(ok, nok, m, compare_png[m], &err) < 0) {
        fprintf(stderr, "report: warning: comparison chart: %s\n", err.msg);
        free(compare_png[m]);
        compare_png[m] = NULL;
      }
    }

  char *csv = malloc(plen), *html = malloc(plen);
  if (!csv || !html) {
    fprintf(stderr, "report: out of memory\n");
    status = 1;
  } else {
    snprintf(csv, plen, "%s/report.csv", out);
    snprintf(html, plen, "%s/report.html", out);
    verr_t err = {{0}};
    if (rep_write_csv(ok, nok, csv, &err) < 0 ||
        rep_write_html(ok, nok, (const char *const *)force_png, (const char *const *)compare_png, html, &err) < 0) {
      fprintf(stderr, "report: error: %s\n", err.msg);
      status = 1;
    } else if (!quiet) {
      fprintf(stderr, "report: wrote %s and %s (%d recording(s))\n", html, csv, nok);
    }
  }
  free(csv);
  free(html);
  for (int i = 0; i < MAX_RECORDINGS; i++) free(force_png[i]);
  for (int m = 0; m < REP_NMEASURES; m++) free(compare_png[m]);
  for (int i = 0; i < nin; i++) rep_recording_free(&recs[i]);
  free(recs);
  plot_cleanup();
  return status;
}
