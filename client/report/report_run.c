/* SPDX-License-Identifier: Apache-2.0 */
#include "report_run.h"

#include <errno.h>
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

/* Label as a file-name part: [A-Za-z0-9_-], anything else becomes '_'. */
static void file_part(const char *label, char *out, size_t size) {
  size_t i = 0;
  for (; label[i] && i + 1 < size; i++) {
    char ch = label[i];
    out[i] = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '-' ? ch : '_';
  }
  out[i] = 0;
}

typedef struct section {
  const char *path;
  char label[64];
  char seat[128]; /* "" = the whole recording */
} section_t;

/* The sections: one per recording, or one per seat of a recording whose
 * servers wrote in several partitions (a lab). */
static int plan_sections(const report_options_t *o, section_t *sec, int max, bool *lab) {
  int n = 0;
  for (int i = 0; i < o->nin && n < max; i++) {
    char seats[MAX_SECTIONS][128];
    verr_t err = {{0}};
    int ns = rep_recording_seats(o->in[i].path, seats, MAX_SECTIONS, &err);
    if (ns < 2) {
      sec[n].path = o->in[i].path;
      snprintf(sec[n].label, sizeof sec[n].label, "%s", o->in[i].label);
      sec[n++].seat[0] = 0;
      continue;
    }
    *lab = true;
    if (!o->quiet) fprintf(stderr, "report: %s holds %d seats: one section each\n", o->in[i].path, ns);
    for (int k = 0; k < ns && n < max; k++, n++) {
      const char *tail = strrchr(seats[k], '/');
      sec[n].path = o->in[i].path;
      snprintf(sec[n].label, sizeof sec[n].label, "%.30s %.30s", o->in[i].label, tail ? tail + 1 : seats[k]);
      snprintf(sec[n].seat, sizeof sec[n].seat, "%s", seats[k]);
    }
  }
  return n;
}

int report_run(const report_options_t *o) {
  const char *out = o->out;
  bool quiet = o->quiet;
  if (mkdir(out, 0755) != 0 && errno != EEXIST) {
    fprintf(stderr, "report: cannot create output directory %s: %s\n", out, strerror(errno));
    return 1;
  }
  static section_t sec[MAX_SECTIONS];
  bool lab = false;
  int nin = plan_sections(o, sec, MAX_SECTIONS, &lab);

  rep_recording_t *recs = calloc((size_t)nin, sizeof *recs);
  const rep_recording_t *ok[MAX_SECTIONS];
  if (!recs) {
    fprintf(stderr, "report: out of memory\n");
    return 1;
  }
  int nok = 0, status = 0;
  for (int i = 0; i < nin; i++) {
    if (!quiet) fprintf(stderr, "report: reading %s (%s)\n", sec[i].path, sec[i].label);
    verr_t err = {{0}};
    rep_recording_t *r = &recs[i];
    if (rep_recording_load(r, sec[i].path, sec[i].label, sec[i].seat[0] ? sec[i].seat : NULL, &err) < 0) {
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
      fprintf(stderr, "report: warning: %s: %.*s\n", sec[i].path, len, w);
      w += len + (nl ? 1 : 0);
    }
    if (!quiet) {
      size_t nf = 0, nc = 0;
      for (int t = 0; t < r->ntools; t++) nf += r->tools[t].nforce, nc += r->tools[t].ncmd;
      int nfail = 0;
      rep_outcome_t v = rep_verdict(&o->limits, r, &nfail);
      fprintf(stderr,
              "report: %s: %zu force samples, %zu commands, %zu events; peak %.2f N, contact %.2f s, above MPF "
              "%.2f s, path %.1f cm; verdict %s",
              r->label, nf, nc, r->nevents, r->sum.peak_force, r->sum.contact_time, r->sum.time_above[THR_MPF],
              r->sum.path_length * 100, rep_outcome_name(v));
      if (nfail) fprintf(stderr, " (%d limit(s) failed)", nfail);
      fprintf(stderr, "\n");
      for (size_t t = 0; t < r->ntasks; t++)
        if (isfinite(r->tasks[t].end))
          fprintf(stderr, "report: %s: task %s (id %d) %.3f s\n", r->label, r->tasks[t].name, r->tasks[t].id,
                  r->tasks[t].end - r->tasks[t].start);
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
  char *force_png[MAX_SECTIONS] = {0}, *compare_png[REP_NMEASURES] = {0}, *overlay_png = NULL;
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
  if (nok >= 2 && (overlay_png = malloc(plen)) != NULL) {
    snprintf(overlay_png, plen, "%s/compare_force.png", out);
    verr_t err = {{0}};
    if (rep_chart_force_overlay(ok, nok, overlay_png, &err) < 0) {
      fprintf(stderr, "report: warning: force comparison chart: %s\n", err.msg);
      free(overlay_png);
      overlay_png = NULL;
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
    const rep_charts_t charts = {(const char *const *)force_png, (const char *const *)compare_png, overlay_png};
    const rep_layout_t layout = {&o->limits, lab};
    if (rep_write_csv(ok, nok, &o->limits, csv, &err) < 0 ||
        rep_write_html(ok, nok, &charts, &layout, html, &err) < 0) {
      fprintf(stderr, "report: error: %s\n", err.msg);
      status = 1;
    } else if (!quiet) {
      fprintf(stderr, "report: wrote %s and %s (%d section(s))\n", html, csv, nok);
    }
  }
  free(csv);
  free(html);
  for (int i = 0; i < MAX_SECTIONS; i++) free(force_png[i]);
  free(overlay_png);
  for (int m = 0; m < REP_NMEASURES; m++) free(compare_png[m]);
  for (int i = 0; i < nin; i++) rep_recording_free(&recs[i]);
  free(recs);
  plot_cleanup();
  return status;
}
