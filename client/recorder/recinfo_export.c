/* SPDX-License-Identifier: Apache-2.0 */
#include "recinfo_export.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "export_scene.h"
#include "mcap_writer.h"
#include "recording/rec_cdr.h"
#include "recording/rec_idl.h"
#include "recording/rec_types.h"
#include "recording/rec_writers.h"
#include "recording/recfile.h"
#include "recording/recording.h"

export_format_t export_format_parse(const char *name) {
  if (strcmp(name, "mcap") == 0) return EXPORT_MCAP;
  if (strcmp(name, "csv") == 0) return EXPORT_CSV;
  if (strcmp(name, "jsonl") == 0) return EXPORT_JSONL;
  return EXPORT_NONE;
}

/* One MCAP channel: a topic in one partition. */
typedef struct chan {
  int64_t topic_id;
  char partitions[256];
  uint32_t seq;
} chan_t;

typedef struct mcap_ctx {
  mcap_writer_t *w;
  recfile_t *rf;
  export_scene_t *scene; /* --foxglove-scene, or NULL */
  const rec_writer_t *writers;
  size_t nwriters;
  chan_t *chans;
  size_t nchans;
  rt_model_t *models; /* per topic (recfile_topic order): its recorded type; top NULL when unreadable */
  rt_str_t x1;        /* the message re-encoded as XCDR1 */
  uint64_t messages, other_rows, reencoded, not_reencoded;
  verr_t err;
  bool failed;
} mcap_ctx_t;

static const char *partition_of(const rec_writer_t *w, size_t n, int64_t id) {
  const rec_writer_t *x = rec_writer_find(w, n, id);
  return x ? x->partitions : "";
}

static int on_mcap_row(void *arg, const recfile_row_t *row) {
  mcap_ctx_t *c = arg;
  if (row->kind != REC_KIND_DATA) {
    c->other_rows++;
    return 0;
  }
  const char *part = partition_of(c->writers, c->nwriters, row->writer_id);
  size_t k = 0;
  while (k < c->nchans && !(c->chans[k].topic_id == row->topic_id && strcmp(c->chans[k].partitions, part) == 0)) k++;
  if (k == c->nchans) { /* a writer the writers table lost: the topic's first channel */
    k = 0;
    while (k < c->nchans && c->chans[k].topic_id != row->topic_id) k++;
    if (k == c->nchans) {
      c->other_rows++;
      return 0;
    }
  }
  uint64_t t = row->source_ts_ns > 0 ? (uint64_t)row->source_ts_ns : 0;
  size_t ti = 0;
  while (ti < recfile_topic_count(c->rf) && recfile_topic(c->rf, ti)->id != row->topic_id) ti++;
  /* XCDR2 samples go out as XCDR1 (docs/dds.md "Schema evolution": Foxglove's
   * reader misreads XCDR2 collections of structs); one that does not fit its
   * type goes out as recorded, counted. */
  const void *msg = row->cdr;
  size_t len = row->cdr_len;
  if (ti < recfile_topic_count(c->rf) && c->models[ti].top && row->cdr_len >= 4 &&
      ((const unsigned char *)row->cdr)[1] >= 6) {
    verr_t e = {{0}};
    c->x1.len = 0;
    if (rt_cdr_to_xcdr1(c->models[ti].top, row->cdr, row->cdr_len, &c->x1, &e) == 0) {
      msg = c->x1.s, len = c->x1.len;
      c->reencoded++;
    } else if (c->not_reencoded++ == 0) {
      fprintf(stderr, "recinfo: warning: row %lld (%s): not re-encoded as XCDR1 (%s); exported as recorded\n",
              (long long)row->id, recfile_topic(c->rf, ti)->name, e.msg);
    }
  }
  if (mcap_message(c->w, (uint16_t)(k + 1), c->chans[k].seq++, t, t, msg, len, &c->err) < 0) {
    c->failed = true;
    return 1;
  }
  c->messages++;
  if (c->scene) {
    const char *topic = ti < recfile_topic_count(c->rf) ? recfile_topic(c->rf, ti)->name : "";
    if (export_scene_row(c->scene, topic, row, &c->err) < 0) {
      c->failed = true;
      return 1;
    }
  }
  return 0;
}

/* Channels: every (topic, partition) its writers used; a topic without
 * writers gets one channel of no partition. */
static int plan_channels(recfile_t *rf, const rec_writer_t *w, size_t nw, chan_t **out, size_t *n) {
  size_t cap = recfile_topic_count(rf) + nw + 1;
  chan_t *c = calloc(cap, sizeof *c);
  if (!c) return -1;
  size_t nc = 0;
  for (size_t i = 0; i < recfile_topic_count(rf); i++) {
    const recfile_topic_t *t = recfile_topic(rf, i);
    size_t first = nc;
    for (size_t k = 0; k < nw; k++) {
      if (w[k].topic_id != t->id) continue;
      bool seen = false;
      for (size_t j = first; j < nc; j++) seen |= strcmp(c[j].partitions, w[k].partitions) == 0;
      if (!seen && nc < cap) {
        c[nc].topic_id = t->id;
        snprintf(c[nc++].partitions, sizeof c->partitions, "%s", w[k].partitions);
      }
    }
    if (nc == first && nc < cap) c[nc++].topic_id = t->id;
  }
  *out = c;
  *n = nc > 65535 ? 65535 : nc;
  return 0;
}

static int export_mcap(recfile_t *rf, const char *out, bool scene, bool quiet) {
  const char *path = recfile_path(rf);
  verr_t err = {{0}};
  rec_writer_t *writers = NULL;
  size_t nw = 0;
  if (rec_writers_load(rf, &writers, &nw, &err) < 0) fprintf(stderr, "recinfo: warning: %s\n", err.msg);
  mcap_ctx_t c = {.writers = writers, .nwriters = nw, .rf = rf};
  int status = 0;
  char library[64];
  snprintf(library, sizeof library, "viscera-recinfo %s", cli_version());
  if (plan_channels(rf, writers, nw, &c.chans, &c.nchans) < 0 || mcap_open(&c.w, out, "", library, &err) < 0) {
    fprintf(stderr, "recinfo: %s\n", err.msg[0] ? err.msg : "out of memory");
    free(writers);
    free(c.chans);
    return 1;
  }
  size_t ntopics = recfile_topic_count(rf), nschemas = 0;
  uint16_t *schema_of = calloc(ntopics ? ntopics : 1, sizeof *schema_of);
  c.models = calloc(ntopics ? ntopics : 1, sizeof *c.models);
  if (!c.models) free(schema_of), schema_of = NULL;
  for (size_t i = 0; schema_of && i < ntopics && status == 0; i++) {
    const recfile_topic_t *t = recfile_topic(rf, i);
    rt_model_t *m = &c.models[i];
    rt_str_t idl = {0};
    verr_t e = {{0}};
    if (rt_model_load_topic(m, rf, t, &e) < 0 || rt_idl_text(m, &idl, &e) < 0) {
      fprintf(stderr, "recinfo: warning: %s: topic %s: no schema (%s); its messages are exported without one\n", path,
              t->name, e.msg);
      rt_model_free(m);
      memset(m, 0, sizeof *m);
    } else {
      schema_of[i] = (uint16_t)++nschemas;
      if (mcap_schema(c.w, schema_of[i], t->type_name, "omgidl", idl.s, idl.len, &err) < 0) status = 1;
    }
    rt_str_free(&idl);
  }
  for (size_t k = 0; schema_of && k < c.nchans && status == 0; k++) {
    const recfile_topic_t *t = NULL;
    size_t ti = 0;
    for (; ti < ntopics; ti++)
      if ((t = recfile_topic(rf, ti))->id == c.chans[k].topic_id) break;
    /* Several partitions of a topic (a lab's seats): "partition/topic". */
    bool several =
        (k > 0 && c.chans[k - 1].topic_id == t->id) || (k + 1 < c.nchans && c.chans[k + 1].topic_id == t->id);
    char name[600];
    snprintf(name, sizeof name, "%s%s%s", several ? c.chans[k].partitions : "", several ? "/" : "", t->name);
    const char *meta[] = {"dds_topic", t->name, "partition", c.chans[k].partitions, "type", t->type_name};
    if (mcap_channel(c.w, (uint16_t)(k + 1), schema_of[ti], name, "cdr", meta, 3, &err) < 0) status = 1;
  }
  if (status == 0 && schema_of && scene &&
      !(c.scene = export_scene_open(c.w, (uint16_t)(nschemas + 1), (uint16_t)(c.nchans + 1), &err)))
    status = 1;
  recfile_scan_report_t rep;
  if (status == 0 && schema_of) {
    recfile_scan(rf, 0, true, on_mcap_row, &c, &rep);
    if (c.failed) err = c.err, status = 1;
    if (rep.damaged || rep.invalid) {
      fprintf(stderr, "recinfo: %s: damaged: %s; %llu unreadable rows; exported what was readable\n", path,
              rep.first_error[0] ? rep.first_error : "invalid rows", (unsigned long long)rep.invalid);
      status = 1;
    }
  }
  if (!schema_of) status = 1, verr_set(&err, "out of memory");
  uint64_t scene_msgs = 0, scene_skipped = 0;
  export_scene_close(c.scene, &scene_msgs, &scene_skipped);
  if (scene && !quiet)
    fprintf(stderr,
            "recinfo: %s: %llu Foxglove scene updates on /viscera/scene; %llu mesh samples without their keyframe "
            "skipped\n",
            out, (unsigned long long)scene_msgs, (unsigned long long)scene_skipped);
  verr_t cerr = {{0}};
  if (mcap_close(c.w, &cerr) < 0 && status == 0) err = cerr, status = 1;
  if (status && err.msg[0]) fprintf(stderr, "recinfo: %s\n", err.msg);
  if (!quiet)
    fprintf(stderr,
            "recinfo: %s: %llu messages in %zu channels, %zu schemas (OMG IDL)%s%llu dispose/unregister rows "
            "not exported\n",
            out, (unsigned long long)c.messages, c.nchans, nschemas, c.other_rows ? "; " : "; ",
            (unsigned long long)c.other_rows);
  if (!quiet && (c.reencoded || c.not_reencoded))
    fprintf(stderr, "recinfo: %s: %llu XCDR2 messages re-encoded as XCDR1, %llu exported as recorded\n", out,
            (unsigned long long)c.reencoded, (unsigned long long)c.not_reencoded);
  for (size_t i = 0; c.models && i < ntopics; i++)
    if (c.models[i].top) rt_model_free(&c.models[i]);
  free(c.models);
  rt_str_free(&c.x1);
  free(schema_of);
  free(c.chans);
  free(writers);
  return status;
}

typedef struct table_ctx {
  FILE *f;
  export_format_t fmt;
  const rt_type_t *top;
  const rec_writer_t *writers;
  size_t nwriters;
  rt_str_t line;
  uint64_t rows, bad;
  verr_t first_bad;
  bool write_failed;
} table_ctx_t;

static int on_table_row(void *arg, const recfile_row_t *row) {
  table_ctx_t *c = arg;
  if (row->kind != REC_KIND_DATA) return 0;
  const char *part = partition_of(c->writers, c->nwriters, row->writer_id);
  c->line.len = 0;
  if (c->line.s) c->line.s[0] = 0;
  verr_t e = {{0}};
  int r;
  if (c->fmt == EXPORT_CSV) {
    rt_str_printf(&c->line, "%lld,\"%s\",", (long long)row->source_ts_ns, part);
    r = rt_cdr_csv(c->top, row->cdr, row->cdr_len, &c->line, &e);
  } else {
    rt_str_printf(&c->line, "{\"source_time_ns\":%lld,\"partition\":\"%s\",\"sample\":", (long long)row->source_ts_ns,
                  part);
    r = rt_cdr_json(c->top, row->cdr, row->cdr_len, &c->line, &e);
    rt_str_append(&c->line, "}", 1);
  }
  if (r < 0) {
    if (c->bad++ == 0) verr_set(&c->first_bad, "sample %lld: %s", (long long)row->id, e.msg);
    return 0;
  }
  rt_str_append(&c->line, "\n", 1);
  if (c->line.oom || fwrite(c->line.s, 1, c->line.len, c->f) != c->line.len) {
    c->write_failed = true;
    return 1;
  }
  c->rows++;
  return 0;
}

static int export_table(recfile_t *rf, export_format_t fmt, const char *out, const char *topic, bool quiet) {
  const char *path = recfile_path(rf);
  if (!topic) {
    fprintf(stderr, "recinfo: --export %s needs --topic NAME (one topic per file)\n",
            fmt == EXPORT_CSV ? "csv" : "jsonl");
    return 2;
  }
  const recfile_topic_t *t = recfile_topic_by_name(rf, topic);
  if (!t) {
    fprintf(stderr, "recinfo: %s: no topic '%s' in this recording\n", path, topic);
    return 2;
  }
  rt_model_t m;
  verr_t err = {{0}};
  if (rt_model_load_topic(&m, rf, t, &err) < 0) {
    fprintf(stderr, "recinfo: %s: topic %s: %s\n", path, topic, err.msg);
    rt_model_free(&m);
    return 1;
  }
  bool to_stdout = strcmp(out, "-") == 0;
  FILE *f = to_stdout ? stdout : fopen(out, "w");
  if (!f) {
    fprintf(stderr, "recinfo: %s: cannot create: %s\n", out, strerror(errno));
    rt_model_free(&m);
    return 1;
  }
  rec_writer_t *writers = NULL;
  size_t nw = 0;
  if (rec_writers_load(rf, &writers, &nw, &err) < 0) fprintf(stderr, "recinfo: warning: %s\n", err.msg);
  table_ctx_t c = {.f = f, .fmt = fmt, .top = m.top, .writers = writers, .nwriters = nw};
  if (fmt == EXPORT_CSV) {
    rt_str_t h = {0};
    rt_csv_header(m.top, &h);
    fprintf(f, "source_time_ns,partition,%s\n", h.s ? h.s : "");
    rt_str_free(&h);
  }
  recfile_scan_report_t rep;
  recfile_scan(rf, t->id, true, on_table_row, &c, &rep);
  int status = 0;
  if (c.bad) {
    fprintf(stderr, "recinfo: %s: %llu sample(s) of %s did not decode and were left out (first: %s)\n", path,
            (unsigned long long)c.bad, topic, c.first_bad.msg);
    status = 1;
  }
  if (rep.damaged || rep.invalid) {
    fprintf(stderr, "recinfo: %s: damaged: %s; exported what was readable\n", path,
            rep.first_error[0] ? rep.first_error : "invalid rows");
    status = 1;
  }
  if ((to_stdout ? fflush(f) : fclose(f)) != 0 || c.write_failed) {
    fprintf(stderr, "recinfo: %s: write failed: %s\n", out, strerror(errno));
    status = 1;
  }
  if (!quiet) fprintf(stderr, "recinfo: %s: %llu rows of %s\n", out, (unsigned long long)c.rows, topic);
  rt_str_free(&c.line);
  free(writers);
  rt_model_free(&m);
  return status;
}

int recinfo_export(const char *path, export_format_t fmt, const char *out, const char *topic, bool scene, bool quiet) {
  verr_t err = {{0}};
  recfile_t *rf = NULL;
  if (recfile_open(&rf, path, &err) < 0) {
    fprintf(stderr, "recinfo: %s\n", err.msg);
    return 1;
  }
  int r = fmt == EXPORT_MCAP ? export_mcap(rf, out, scene, quiet) : export_table(rf, fmt, out, topic, quiet);
  if (recfile_damaged(rf) && r == 0) r = 1;
  recfile_close(rf);
  return r;
}
