/* SPDX-License-Identifier: Apache-2.0 */
#include "report_write.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "measure_table.h"

/* CSV field: quoted, inner quotes doubled (labels and paths are user text). */
static void csv_text(FILE *f, const char *s) {
  fputc('"', f);
  for (; *s; s++) {
    if (*s == '"') fputc('"', f);
    fputc(*s == '\n' ? ' ' : *s, f);
  }
  fputc('"', f);
}

static void csv_num(FILE *f, const char *fmt, double v) {
  if (isfinite(v)) fprintf(f, fmt, v);
}

static void utc_string(int64_t wall_ns, char *buf, size_t size) {
  time_t t = (time_t)(wall_ns / 1000000000);
  struct tm tm;
  if (wall_ns <= 0 || !gmtime_r(&t, &tm) || !strftime(buf, size, "%Y-%m-%d %H:%M:%S UTC", &tm))
    snprintf(buf, size, "?");
}

static size_t count_lines(const char *s) {
  size_t n = 0;
  for (; *s; s++) n += *s == '\n';
  return n;
}

/* The time the recording's cuts took (those with both ends) and the
 * topology changes they made (those that ended); NAN when no cut gives it. */
static void cut_totals(const rep_recording_t *r, double *time, double *changes) {
  size_t nt = 0, nc = 0;
  *time = *changes = 0;
  for (size_t i = 0; i < r->ncuts; i++) {
    const rep_cut_t *c = &r->cuts[i];
    if (isfinite(c->t_begin) && isfinite(c->t_end)) *time += c->t_end - c->t_begin, nt++;
    if (isfinite(c->changes)) *changes += c->changes, nc++;
  }
  if (!nt) *time = NAN;
  if (!nc) *changes = NAN;
}

int rep_write_csv(const rep_recording_t *const *recs, int n, const rep_limits_t *limits, const char *path,
                  verr_t *err) {
  FILE *f = fopen(path, "w");
  if (!f) return verr_set(err, "%s: cannot create: %s", path, strerror(errno));
  fprintf(f, "label,file,scene,partition,identity,start_utc,complete");
  for (int m = 0; m < REP_NMEASURES; m++) fprintf(f, ",%s", rep_measure(m)->key);
  fprintf(f, ",ST_N,MPF_N,SFT_N,crossings_source,tasks,cuts,cut_time_s,cut_topology_changes,verdict,failed,warnings\n");
  for (int i = 0; i < n; i++) {
    const rep_recording_t *r = recs[i];
    char start[40];
    utc_string(r->session.start_wall_ns, start, sizeof start);
    csv_text(f, r->label);
    fputc(',', f);
    csv_text(f, r->path);
    fputc(',', f);
    csv_text(f, r->scene[0] ? r->scene : r->session.scene);
    fputc(',', f);
    csv_text(f, r->seat[0] ? r->seat : r->session.partition);
    fputc(',', f);
    csv_text(f, r->identity);
    fprintf(f, ",%s,%d", start, r->damaged || !r->session.has_end ? 0 : 1);
    for (int m = 0; m < REP_NMEASURES; m++) {
      fputc(',', f);
      csv_num(f, "%.6g", rep_measure_value(r, m));
    }
    for (int k = 0; k < THR_COUNT; k++) {
      fputc(',', f);
      csv_num(f, "%.4g", r->sum.levels[k] > 0 ? r->sum.levels[k] : NAN); /* empty: not set */
    }
    fprintf(f, ",%s,", r->sum.crossings_from_events ? "events" : "force_trace");
    /* tasks as name=seconds;... (unfinished: name=incomplete) */
    char tasks[1024] = "";
    size_t len = 0;
    for (size_t t = 0; t < r->ntasks && len + 80 < sizeof tasks; t++) {
      const rep_task_t *tk = &r->tasks[t];
      if (isfinite(tk->end))
        len +=
            (size_t)snprintf(tasks + len, sizeof tasks - len, "%s%s=%.3f", t ? ";" : "", tk->name, tk->end - tk->start);
      else
        len += (size_t)snprintf(tasks + len, sizeof tasks - len, "%s%s=incomplete", t ? ";" : "", tk->name);
    }
    csv_text(f, tasks);
    /* cuts: how many began or ended, their time (those with both ends) and
     * topology changes (those that ended); empty when there was none */
    double cut_time = 0, cut_changes = 0;
    cut_totals(r, &cut_time, &cut_changes);
    if (r->ncuts) {
      fprintf(f, ",%zu,", r->ncuts);
      csv_num(f, "%.3f", cut_time);
      fputc(',', f);
      csv_num(f, "%.0f", cut_changes);
    } else
      fputs(",,,", f);
    /* verdict, and the limits that failed as "KEY<=BOUND;..." */
    char failed[512] = "";
    size_t fl = 0;
    for (int k = 0; k < limits->n && fl + 80 < sizeof failed; k++) {
      double v, b;
      if (rep_limit_check(&limits->l[k], r, &v, &b) == REP_FAIL)
        fl += (size_t)snprintf(failed + fl, sizeof failed - fl, "%s%s", fl ? ";" : "", limits->l[k].text);
    }
    fprintf(f, ",%s,", rep_outcome_name(rep_verdict(limits, r, NULL)));
    csv_text(f, failed);
    fprintf(f, ",%zu\n", count_lines(r->warnings));
  }
  if (fclose(f) != 0) return verr_set(err, "%s: write failed: %s", path, strerror(errno));
  return 0;
}

static void html_text(FILE *f, const char *s) {
  for (; *s; s++) {
    switch (*s) {
    case '<':
      fputs("&lt;", f);
      break;
    case '>':
      fputs("&gt;", f);
      break;
    case '&':
      fputs("&amp;", f);
      break;
    case '"':
      fputs("&quot;", f);
      break;
    default:
      fputc(*s, f);
    }
  }
}

/* <img> with the PNG inlined as base64; false when the file is unreadable. */
static int html_png(FILE *f, const char *png, const char *alt, verr_t *err) {
  static const char B64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  FILE *in = fopen(png, "rb");
  if (!in) return verr_set(err, "%s: cannot read: %s", png, strerror(errno));
  fputs("<img alt=\"", f);
  html_text(f, alt);
  fputs("\" src=\"data:image/png;base64,", f);
  unsigned char b[3];
  size_t k;
  while ((k = fread(b, 1, 3, in)) > 0) {
    if (k < 3) memset(b + k, 0, 3 - k);
    char o[4] = {B64[b[0] >> 2], B64[((b[0] & 3) << 4) | (b[1] >> 4)], B64[((b[1] & 15) << 2) | (b[2] >> 6)],
                 B64[b[2] & 63]};
    if (k < 3) o[3] = '=';
    if (k < 2) o[2] = '=';
    fwrite(o, 1, 4, f);
    if (k < 3) break;
  }
  int rd_err = ferror(in);
  fclose(in);
  fputs("\">\n", f);
  if (rd_err) return verr_set(err, "%s: read error", png);
  return 0;
}

static void html_value(FILE *f, const rep_recording_t *r, int m) {
  const rep_measure_def_t *d = rep_measure(m);
  double v = rep_measure_value(r, m);
  if (!isfinite(v)) {
    fputs("<td class=na>n/a</td>", f);
    return;
  }
  fputs("<td>", f);
  fprintf(f, d->format, v);
  if (d->unit[0]) fprintf(f, " %s", d->unit);
  fputs("</td>", f);
}

static const char *STYLE =
    "body{font-family:'DejaVu Sans',Arial,sans-serif;max-width:1000px;margin:24px auto;color:#222;padding:0 12px}"
    "h1{font-size:24px}h2{font-size:19px;border-bottom:2px solid #1f77b4;padding-bottom:3px;margin-top:34px}"
    "h3{font-size:15px;margin:16px 0 4px}"
    ".summary td:nth-child(2),.summary th:nth-child(2){text-align:left}.summary td:first-child{white-space:nowrap}"
    "table{border-collapse:collapse;margin:10px 0}td,th{border:1px solid #ccc;padding:4px 10px;text-align:right}"
    "th{background:#eef3f8}td:first-child,th:first-child{text-align:left}td.na{color:#999}"
    "td.pass{color:#176d2c;font-weight:bold}td.fail{color:#b00020;font-weight:bold}"
    ".verdict{display:inline-block;padding:2px 10px;border-radius:3px;font-weight:bold;color:#fff}"
    ".verdict.pass{background:#2e7d32}.verdict.fail{background:#c62828}.verdict.na{background:#888}"
    ".who{background:#f4f6f9;border-left:4px solid #1f77b4;padding:6px 10px;margin:8px 0}"
    ".warn{background:#fff4e0;border-left:4px solid #e69500;padding:6px 10px;white-space:pre-wrap}"
    ".meta td{text-align:left}.grid{display:flex;flex-wrap:wrap;gap:8px}.grid img{width:440px}"
    "img{max-width:100%}.note{color:#555;font-size:13px}"
    /* Print (the browser's print to PDF): A4, one section per page, no
     * table row or chart cut across pages, colours kept. */
    "@page{size:A4;margin:14mm 12mm}"
    "@media print{body{max-width:none;margin:0;padding:0;font-size:11px}"
    "h2{break-before:page;page-break-before:always;margin-top:0}h2.first{break-before:auto;page-break-before:auto}"
    "table,img,.who,.warn,tr{break-inside:avoid;page-break-inside:avoid}h2,h3{break-after:avoid;page-break-after:avoid}"
    ".grid img{width:48%}td,th{padding:2px 6px}.note{font-size:9px}"
    "*{-webkit-print-color-adjust:exact;print-color-adjust:exact}}";

static const char *outcome_class(rep_outcome_t o) { return o == REP_PASS ? "pass" : o == REP_FAIL ? "fail" : "na"; }

static void html_verdict_badge(FILE *f, rep_outcome_t v) {
  fprintf(f, "<span class=\"verdict %s\">%s</span>", outcome_class(v), rep_outcome_name(v));
}

static void html_number(FILE *f, int m, double v) {
  const rep_measure_def_t *d = rep_measure(m);
  fprintf(f, d->format, v);
  if (d->unit[0]) fprintf(f, " %s", d->unit);
}

static void html_verdict(FILE *f, const rep_recording_t *r, const rep_limits_t *ls) {
  int nfail = 0;
  rep_outcome_t v = rep_verdict(ls, r, &nfail);
  fputs("<h3>Verdict ", f);
  html_verdict_badge(f, v);
  fputs("</h3>\n<table><tr><th>measure</th><th>value</th><th>limit</th><th>result</th></tr>\n", f);
  for (int i = 0; i < ls->n; i++) {
    const rep_limit_t *l = &ls->l[i];
    double val, b;
    rep_outcome_t o = rep_limit_check(l, r, &val, &b);
    fputs("<tr><td>", f);
    html_text(f, rep_measure(l->measure)->title);
    fputs("</td><td>", f);
    if (isfinite(val))
      html_number(f, l->measure, val);
    else
      fputs("n/a", f);
    fprintf(f, "</td><td>%s ", l->upper ? "&le;" : "&ge;");
    if (isfinite(b))
      html_number(f, l->measure, b);
    else
      fputs("n/a", f);
    if (l->level >= 0) fprintf(f, " (%s)", strchr(l->text, l->upper ? '<' : '>') + 3);
    fprintf(f, "</td><td class=%s>%s</td></tr>\n", outcome_class(o), rep_outcome_name(o));
  }
  fputs("</table>\n", f);
}

/* One row per section: who, the key measures, tasks and the verdict. */
static void html_summary(FILE *f, const rep_recording_t *const *recs, int n, const rep_layout_t *lay) {
  fprintf(f, "<h2 class=first id=summary>%s</h2>\n", lay->lab ? "Lab summary" : "Summary");
  fputs(
      "<table class=summary><tr><th>trainee</th><th>who</th><th>peak force</th><th>contact time</th><th>above MPF</th>"
      "<th>tasks completed</th><th>verdict</th></tr>\n",
      f);
  for (int i = 0; i < n; i++) {
    const rep_recording_t *r = recs[i];
    fprintf(f, "<tr><td><a href=\"#s%d\">", i + 1);
    html_text(f, r->label);
    fputs("</a></td><td>", f);
    html_text(f, r->identity);
    fputs("</td>", f);
    html_value(f, r, 0);
    html_value(f, r, 2);
    html_value(f, r, 6);
    size_t done = 0;
    for (size_t t = 0; t < r->ntasks; t++) done += isfinite(r->tasks[t].end);
    fprintf(f, "<td>%zu / %zu</td><td>", done, r->ntasks);
    html_verdict_badge(f, rep_verdict(lay->limits, r, NULL));
    fputs("</td></tr>\n", f);
  }
  fputs("</table>\n", f);
}

/* A tool's thresholds; a level of 0 is one the scene did not set, which
 * must not read as a limit of 0 N. */
static void html_levels(FILE *f, const double levels[THR_COUNT]) {
  bool any = false;
  for (int k = 0; k < THR_COUNT; k++) any |= levels[k] > 0;
  if (!any) {
    fputs("no thresholds set", f);
    return;
  }
  for (int k = 0; k < THR_COUNT; k++) {
    if (levels[k] > 0)
      fprintf(f, "%s%s %.2f N", k ? ", " : "", thr_name((thr_id_t)k), levels[k]);
    else
      fprintf(f, "%s%s not set", k ? ", " : "", thr_name((thr_id_t)k));
  }
}

/* The scalpel's cuts, from the server's events: when each began, how long
 * it lasted, the topology changes it made and the server's words at its end
 * (vertices, incision width). Nothing when the session cut nothing. */
static void html_cuts(FILE *f, const rep_recording_t *r) {
  if (!r->ncuts) return;
  double time, changes;
  cut_totals(r, &time, &changes);
  fprintf(f, "<h3>Cuts</h3>\n<p>%zu cut(s)", r->ncuts);
  if (isfinite(time)) fprintf(f, ", %.3f s of cutting", time);
  if (isfinite(changes)) fprintf(f, ", %.0f topology change(s)", changes);
  fputs(".</p>\n<table><tr><th>cut</th><th>tool</th><th>began</th><th>lasted</th><th>topology changes</th>"
        "<th>at its end (the server's words)</th></tr>\n",
        f);
  for (size_t i = 0; i < r->ncuts; i++) {
    const rep_cut_t *c = &r->cuts[i];
    fprintf(f, "<tr><td>%zu</td><td>", i + 1);
    if (c->tool >= 0 && c->tool < r->ntools && r->tools[c->tool].name[0])
      html_text(f, r->tools[c->tool].name);
    else
      fprintf(f, "#%d", c->tool);
    fputs("</td>", f);
    if (isfinite(c->t_begin))
      fprintf(f, "<td>%.3f s</td>", c->t_begin);
    else
      fputs("<td class=na>not recorded</td>", f);
    if (isfinite(c->t_begin) && isfinite(c->t_end))
      fprintf(f, "<td>%.3f s</td>", c->t_end - c->t_begin);
    else
      fputs("<td class=na>n/a</td>", f);
    if (isfinite(c->changes))
      fprintf(f, "<td>%.0f</td><td>", c->changes);
    else
      fputs("<td class=na>n/a</td><td>", f);
    html_text(f, isfinite(c->t_end) ? c->result : "not ended in the recording");
    fputs("</td></tr>\n", f);
  }
  fputs("</table>\n", f);
}

static int html_section(FILE *f, const rep_recording_t *r, int i, const rep_charts_t *ch, const rep_layout_t *lay,
                        bool first, verr_t *err) {
  fprintf(f, "<h2 id=s%d%s>", i + 1, first ? " class=first" : "");
  html_text(f, r->label);
  fputs("</h2>\n<div class=who><b>Trainee:</b> ", f);
  html_text(f, r->identity);
  fputs("</div>\n<table class=meta>", f);
  char start[40];
  utc_string(r->session.start_wall_ns, start, sizeof start);
  fputs("<tr><td>recording</td><td>", f);
  html_text(f, r->path);
  fputs("</td></tr><tr><td>scene</td><td>", f);
  html_text(f, r->scene[0] ? r->scene : r->session.scene);
  fputs("</td></tr><tr><td>partition</td><td>", f);
  html_text(f, r->seat[0] ? r->seat : r->session.partition);
  fprintf(f, "</td></tr><tr><td>started</td><td>%s</td></tr>", start);
  fprintf(f, "<tr><td>simulated time covered</td><td>%.2f s</td></tr>", r->sum.duration);
  for (int t = 0; t < r->ntools; t++)
    if (r->tools[t].present) {
      fputs("<tr><td>tool ", f);
      html_text(f, r->tools[t].name);
      fprintf(f, "</td><td>%zu force samples, %zu commands; ", r->tools[t].nforce, r->tools[t].ncmd);
      html_levels(f, r->tools[t].levels);
      fputs("</td></tr>", f);
    }
  fputs("</table>\n", f);
  if (r->warnings[0]) {
    fputs("<div class=warn><b>Warnings</b> (the figures cover what was readable):\n", f);
    html_text(f, r->warnings);
    fputs("</div>\n", f);
  }
  html_verdict(f, r, lay->limits);
  fputs("<h3>Measures</h3>\n<table><tr><th>measure</th><th>value</th></tr>\n", f);
  for (int m = 0; m < REP_NMEASURES; m++) {
    fputs("<tr><td>", f);
    html_text(f, rep_measure(m)->title);
    fputs("</td>", f);
    html_value(f, r, m);
    fputs("</tr>\n", f);
  }
  for (size_t t = 0; t < r->ntasks; t++) {
    const rep_task_t *tk = &r->tasks[t];
    fputs("<tr><td>operation time, task ", f);
    html_text(f, tk->name);
    if (tk->id >= 0) fprintf(f, " (#%d)", tk->id);
    if (isfinite(tk->end))
      fprintf(f, "</td><td>%.3f s%s</td></tr>\n", tk->end - tk->start, tk->started_seen ? "" : " (from session start)");
    else
      fputs("</td><td class=na>not completed</td></tr>\n", f);
  }
  if (r->have_metrics)
    fprintf(f,
            "<tr><td class=note>server's last Metrics (about 1 Hz): above ST / MPF / SFT, contact, mean, peak, "
            "path</td><td class=note>%.2f / %.2f / %.2f s, %.2f s, %.2f N, %.2f N, %.1f cm</td></tr>\n",
            r->metrics_time_above[0], r->metrics_time_above[1], r->metrics_time_above[2], r->metrics_contact_time,
            r->metrics_mean_force, r->metrics_peak, r->metrics_path * 100);
  fprintf(f, "</table>\n<p class=note>crossings from %s.</p>\n",
          r->sum.crossings_from_events ? "the server's SessionEvents"
                                       : "the replayed force trace (no events recorded)");
  html_cuts(f, r);
  if (ch->force_png && ch->force_png[i]) return html_png(f, ch->force_png[i], "contact force over time", err);
  return 0;
}

int rep_write_html(const rep_recording_t *const *recs, int n, const rep_charts_t *ch, const rep_layout_t *lay,
                   const char *path, verr_t *err) {
  FILE *f = fopen(path, "w");
  if (!f) return verr_set(err, "%s: cannot create: %s", path, strerror(errno));
  int ret = 0;
  fprintf(f,
          "<!DOCTYPE html>\n<html lang=en><head><meta charset=utf-8><title>viscera trainee report</title>"
          "<style>%s</style></head><body>\n<h1>Trainee report</h1>\n",
          STYLE);
  fprintf(f,
          "<p class=note>%d section(s)%s. Force measures replay the recorded ContactFeedback (force on the tool "
          "at the server, every physics step) through the server's threshold tracker; times are simulated "
          "time. Thresholds (docs/methods.md B ch. 6): ST sound threshold, MPF maximum palpation force, SFT stopping "
          "force threshold; crossings are upward crossings. Identities are what each process announced (a claim "
          "unless the session ran with DDS Security).</p>\n",
          n, lay->lab ? ", one per seat of the lab" : "");
  if (n >= 2) html_summary(f, recs, n, lay);
  for (int i = 0; i < n && ret == 0; i++) ret = html_section(f, recs[i], i, ch, lay, n < 2 && i == 0, err);
  if (n >= 2 && ret == 0) {
    fputs("<h2 id=comparison>Comparison</h2>\n<table><tr><th>measure</th>", f);
    for (int i = 0; i < n; i++) {
      fputs("<th>", f);
      html_text(f, recs[i]->label);
      fputs("</th>", f);
    }
    fputs("</tr>\n", f);
    for (int m = 0; m < REP_NMEASURES; m++) {
      fputs("<tr><td>", f);
      html_text(f, rep_measure(m)->title);
      fputs("</td>", f);
      for (int i = 0; i < n; i++) html_value(f, recs[i], m);
      fputs("</tr>\n", f);
    }
    fputs("<tr><td>verdict</td>", f);
    for (int i = 0; i < n; i++) {
      rep_outcome_t v = rep_verdict(lay->limits, recs[i], NULL);
      fprintf(f, "<td class=%s>%s</td>", outcome_class(v), rep_outcome_name(v));
    }
    fputs("</tr></table>\n", f);
    if (ch->overlay_png) ret = html_png(f, ch->overlay_png, "contact force of every trainee on one time axis", err);
    fputs("<div class=grid>\n", f);
    for (int m = 0; m < REP_NMEASURES && ret == 0; m++)
      if (ch->compare_png && ch->compare_png[m]) ret = html_png(f, ch->compare_png[m], rep_measure(m)->title, err);
    fputs("</div>\n", f);
  }
  fputs("</body></html>\n", f);
  if (fclose(f) != 0 && ret == 0) ret = verr_set(err, "%s: write failed: %s", path, strerror(errno));
  return ret;
}
