/* SPDX-License-Identifier: Apache-2.0 */
#include "recinfo_run.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "recording/recfile.h"
#include "recording/recording.h"

typedef struct topic_stats {
  int64_t topic_id;
  uint64_t n[3]; /* by rec_kind_t */
  uint64_t inferred;
  uint64_t other_kind;
  uint64_t bytes;
  int64_t first_ts, last_ts;           /* min / max source timestamp, all rows */
  int64_t data_first_ts, data_last_ts; /* same over data rows, for the rate */
} topic_stats_t;

typedef struct writer_state {
  int64_t writer_id;
  int64_t topic_id;
  int64_t last_ts;
  uint64_t decreases;
  int64_t first_bad_id;
} writer_state_t;

typedef struct scan_ctx {
  topic_stats_t *topics;
  size_t ntopics;
  writer_state_t *writers; /* sorted by writer_id */
  size_t nwriters;
  uint64_t unknown_writer_rows;
  bool oom;
} scan_ctx_t;

static topic_stats_t *stats_for(scan_ctx_t *c, int64_t topic_id) {
  for (size_t i = 0; i < c->ntopics; i++)
    if (c->topics[i].topic_id == topic_id) return &c->topics[i];
  topic_stats_t *n = realloc(c->topics, (c->ntopics + 1) * sizeof *n);
  if (!n) return NULL;
  c->topics = n;
  topic_stats_t *t = &c->topics[c->ntopics++];
  memset(t, 0, sizeof *t);
  t->topic_id = topic_id;
  t->first_ts = t->data_first_ts = INT64_MAX;
  t->last_ts = t->data_last_ts = INT64_MIN;
  return t;
}

/* Writers are few and looked up per row: binary search over a sorted
 * array, inserting the rare new one. */
static writer_state_t *writer_for(scan_ctx_t *c, int64_t writer_id, int64_t topic_id) {
  size_t lo = 0, hi = c->nwriters;
  while (lo < hi) {
    size_t mid = lo + (hi - lo) / 2;
    if (c->writers[mid].writer_id < writer_id)
      lo = mid + 1;
    else
      hi = mid;
  }
  if (lo < c->nwriters && c->writers[lo].writer_id == writer_id) return &c->writers[lo];
  writer_state_t *n = realloc(c->writers, (c->nwriters + 1) * sizeof *n);
  if (!n) return NULL;
  c->writers = n;
  memmove(&c->writers[lo + 1], &c->writers[lo], (c->nwriters - lo) * sizeof *n);
  c->nwriters++;
  writer_state_t *w = &c->writers[lo];
  memset(w, 0, sizeof *w);
  w->writer_id = writer_id;
  w->topic_id = topic_id;
  w->last_ts = INT64_MIN;
  return w;
}

static int on_row(void *arg, const recfile_row_t *r) {
  scan_ctx_t *c = arg;
  topic_stats_t *t = stats_for(c, r->topic_id);
  if (!t) {
    c->oom = true;
    return 1;
  }
  if (r->kind >= 0 && r->kind <= 2)
    t->n[r->kind]++;
  else
    t->other_kind++;
  if (r->inferred) t->inferred++;
  t->bytes += r->cdr_len;
  if (r->source_ts_ns < t->first_ts) t->first_ts = r->source_ts_ns;
  if (r->source_ts_ns > t->last_ts) t->last_ts = r->source_ts_ns;
  if (r->kind == REC_KIND_DATA) {
    if (r->source_ts_ns < t->data_first_ts) t->data_first_ts = r->source_ts_ns;
    if (r->source_ts_ns > t->data_last_ts) t->data_last_ts = r->source_ts_ns;
  }
  if (r->writer_id <= 0) {
    c->unknown_writer_rows++;
    return 0;
  }
  /* Only data samples carry their writer's own clock. A dispose/unregister
   * that Cyclone derives from a writer leaving (deleted or lease expired)
   * carries the instance's last update time instead, legitimately older
   * than that writer's latest samples of other instances. */
  if (r->kind != REC_KIND_DATA) return 0;
  writer_state_t *w = writer_for(c, r->writer_id, r->topic_id);
  if (!w) {
    c->oom = true;
    return 1;
  }
  if (r->source_ts_ns < w->last_ts) {
    if (!w->decreases) w->first_bad_id = r->id;
    w->decreases++;
  }
  w->last_ts = r->source_ts_ns;
  return 0;
}

static void fmt_time(char *buf, size_t size, int64_t ns) {
  if (ns == INT64_MAX || ns == INT64_MIN) {
    snprintf(buf, size, "-");
    return;
  }
  time_t sec = (time_t)(ns / 1000000000);
  long ms = (long)((ns % 1000000000) / 1000000);
  if (ms < 0) {
    ms += 1000;
    sec -= 1;
  }
  struct tm tm;
  if (!gmtime_r(&sec, &tm)) {
    snprintf(buf, size, "%lld ns", (long long)ns);
    return;
  }
  char d[32];
  strftime(d, sizeof d, "%Y-%m-%dT%H:%M:%S", &tm);
  snprintf(buf, size, "%s.%03ldZ", d, ms);
}

static void fmt_bytes(char *buf, size_t size, uint64_t b) {
  if (b < 10000)
    snprintf(buf, size, "%llu B", (unsigned long long)b);
  else if (b < 10000000)
    snprintf(buf, size, "%.1f kB", (double)b / 1e3);
  else if (b < 10000000000ULL)
    snprintf(buf, size, "%.1f MB", (double)b / 1e6);
  else
    snprintf(buf, size, "%.1f GB", (double)b / 1e9);
}

static void print_session(const recfile_t *rf) {
  const recfile_session_t *s = recfile_session(rf);
  char t0[64], t1[64];
  printf("recording: %s\n", recfile_path(rf));
  if (!s->valid) {
    printf("session:   (metadata unreadable)\n");
    return;
  }
  fmt_time(t0, sizeof t0, s->start_wall_ns);
  printf("scene:     %s\n", s->scene[0] ? s->scene : "(none)");
  printf("partition: %s\n", s->partition);
  printf("domain:    %d\n", s->domain);
  printf("host:      %s\n", s->hostname[0] ? s->hostname : "(unknown)");
  printf("recorder:  %s (%s), format %d\n", s->recorder_version, s->dds_version, s->format_version);
  printf("start:     %s\n", t0);
  if (s->has_end) {
    fmt_time(t1, sizeof t1, s->end_wall_ns);
    printf("end:       %s (%.3f s)\n", t1, (double)(s->end_wall_ns - s->start_wall_ns) * 1e-9);
  } else {
    printf("end:       (none: the recorder was killed or is still running; the last batch may be missing)\n");
    /* An unfinished recording keeps its newest batches in the WAL file;
     * copying the .db alone would lose them. */
    char wal[4200];
    snprintf(wal, sizeof wal, "%s-wal", recfile_path(rf));
    if (access(wal, F_OK) == 0) printf("note:      part of the data is in %s; keep it next to the .db\n", wal);
  }
}

static void print_participant(void *arg, const recfile_participant_t *p) {
  int *subjects = arg;
  char first[64], left[64];
  fmt_time(first, sizeof first, p->first_seen_wall_ns);
  if (p->left_wall_ns >= 0)
    fmt_time(left, sizeof left, p->left_wall_ns);
  else
    snprintf(left, sizeof left, "(present at end)");
  printf("%-10s %-32s %-24s %-24s %s\n", p->role[0] ? p->role : "-", p->guid, first, left,
         p->user_data[0] ? p->user_data : "(no user data)");
  if (p->subject[0]) {
    printf("%-10s subject: %s\n", "", p->subject);
    (*subjects)++;
  }
}

/* Who took part: an optional table (recordings made before it existed
 * have none, and that is not an error). */
static int print_participants(recfile_t *rf, const char *path) {
  printf("\nparticipants (roles are each process's own claim, see vdds_ident.h):\n");
  printf("%-10s %-32s %-24s %-24s %s\n", "role", "guid", "first seen", "left", "user data");
  int subjects = 0;
  int n = recfile_participants(rf, print_participant, &subjects);
  if (n == -1) {
    printf("(not recorded: this recording predates participant metadata)\n");
  } else if (n == -2) {
    fprintf(stderr, "recinfo: %s: damaged: the participants table cannot be read\n", path);
    return -1;
  } else {
    printf("participants: %d\n", n);
    /* What a subject proves: common/dds/vdds_subject.h. */
    if (subjects)
      printf("certificate subjects: %d, each verified against the participant's authenticated GUID\n", subjects);
    else
      printf("certificate subjects: none (the recorder did not run with DDS Security, or the file predates them)\n");
  }
  return 0;
}

int recinfo_run(const recinfo_options_t *o) {
  if (o->export_format != EXPORT_NONE)
    return recinfo_export(o->path, o->export_format, o->export_out, o->topic, o->foxglove_scene, o->quiet);
  const char *path = o->path, *topic = o->topic;
  bool check_mono = o->check_mono;
  verr_t err = {{0}};
  recfile_t *rf = NULL;
  if (recfile_open(&rf, path, &err) < 0) {
    fprintf(stderr, "recinfo: %s\n", err.msg);
    return EXIT_BAD_FILE;
  }
  int status = EXIT_OK;
  if (recfile_warnings(rf)[0]) fprintf(stderr, "recinfo: %s: warning: %s\n", path, recfile_warnings(rf));

  int64_t only = 0;
  if (topic) {
    const recfile_topic_t *t = recfile_topic_by_name(rf, topic);
    if (!t) {
      fprintf(stderr, "recinfo: %s: no topic '%s' in this recording (%zu topics)\n", path, topic,
              recfile_topic_count(rf));
      recfile_close(rf);
      return EXIT_BAD_FILE;
    }
    only = t->id;
  }

  print_session(rf);
  if (print_participants(rf, path) < 0) status = EXIT_BAD_FILE;
  scan_ctx_t ctx = {0};
  recfile_scan_report_t rep;
  recfile_scan(rf, only, false, on_row, &ctx, &rep);

  /* Topics from the topics table first (including silent ones), then any
   * topic id the samples mention that the table lost. */
  printf("\n%-28s %-28s %8s %8s %7s %10s %-24s %-24s %9s %4s\n", "topic", "type", "samples", "disposes", "unregs",
         "bytes", "first source ts", "last source ts", "rate/s", "wrtr");
  uint64_t total = 0, total_bytes = 0;
  size_t printed = 0;
  for (size_t pass = 0; pass < 2; pass++) {
    size_t n = pass == 0 ? recfile_topic_count(rf) : ctx.ntopics;
    for (size_t i = 0; i < n; i++) {
      const recfile_topic_t *t = NULL;
      topic_stats_t *st = NULL;
      int64_t id;
      if (pass == 0) {
        t = recfile_topic(rf, i);
        if (only && t->id != only) continue;
        id = t->id;
        for (size_t j = 0; j < ctx.ntopics; j++)
          if (ctx.topics[j].topic_id == id) st = &ctx.topics[j];
      } else {
        st = &ctx.topics[i];
        id = st->topic_id;
        bool known = false;
        for (size_t j = 0; j < recfile_topic_count(rf); j++)
          if (recfile_topic(rf, j)->id == id) known = true;
        if (known) continue;
      }
      topic_stats_t zero = {.topic_id = id,
                            .first_ts = INT64_MAX,
                            .last_ts = INT64_MIN,
                            .data_first_ts = INT64_MAX,
                            .data_last_ts = INT64_MIN};
      if (!st) st = &zero;
      char name[300], b[32], f[64], l[64], rate[32], wr[24];
      if (t)
        snprintf(name, sizeof name, "%s", t->name);
      else
        snprintf(name, sizeof name, "(topic id %lld)", (long long)id);
      fmt_bytes(b, sizeof b, st->bytes);
      fmt_time(f, sizeof f, st->first_ts);
      fmt_time(l, sizeof l, st->last_ts);
      uint64_t ns = st->n[0] + st->n[1] + st->n[2] + st->other_kind;
      /* Mean data rate; meaningless for a burst (e.g. keyframes written
       * back to back), so only over a span of at least 10 ms. */
      if (st->n[0] > 1 && st->data_last_ts - st->data_first_ts >= 10000000)
        snprintf(rate, sizeof rate, "%.1f",
                 (double)(st->n[0] - 1) / ((double)(st->data_last_ts - st->data_first_ts) * 1e-9));
      else
        snprintf(rate, sizeof rate, "-");
      if (t && t->writers >= 0)
        snprintf(wr, sizeof wr, "%lld", (long long)t->writers);
      else
        snprintf(wr, sizeof wr, "?");
      printf("%-28s %-28s %8llu %8llu %7llu %10s %-24s %-24s %9s %4s\n", name, t ? t->type_name : "?",
             (unsigned long long)st->n[0], (unsigned long long)st->n[1], (unsigned long long)st->n[2], b, f, l, rate,
             wr);
      if (st->inferred)
        printf("%-28s (%llu dispose/unregister rows inferred from instance state)\n", "",
               (unsigned long long)st->inferred);
      total += ns;
      total_bytes += st->bytes;
      printed++;
    }
  }
  char tb[32];
  fmt_bytes(tb, sizeof tb, total_bytes);
  printf("total: %llu samples, %s in %zu topics\n", (unsigned long long)total, tb, printed);
  if (ctx.unknown_writer_rows)
    printf("note: %llu samples have no known writer\n", (unsigned long long)ctx.unknown_writer_rows);

  if (ctx.oom) {
    fprintf(stderr, "recinfo: %s: out of memory while summarising\n", path);
    status = EXIT_BAD_FILE;
  }
  if (recfile_damaged(rf)) status = EXIT_BAD_FILE;
  if (rep.invalid) {
    fprintf(stderr, "recinfo: %s: damaged: %llu impossible sample rows (zeroed or garbled data) skipped\n", path,
            (unsigned long long)rep.invalid);
    status = EXIT_BAD_FILE;
  }
  if (rep.damaged) {
    fprintf(stderr, "recinfo: %s: damaged: %s; %s (%llu samples read)\n", path, rep.first_error,
            rep.gave_up ? "gave up on the rest of the file" : "skipped the damaged region(s)",
            (unsigned long long)rep.rows);
    status = EXIT_BAD_FILE;
  }
  if (check_mono) {
    uint64_t bad_writers = 0;
    for (size_t i = 0; i < ctx.nwriters; i++) {
      const writer_state_t *w = &ctx.writers[i];
      if (!w->decreases) continue;
      bad_writers++;
      const char *tn = "?";
      for (size_t j = 0; j < recfile_topic_count(rf); j++)
        if (recfile_topic(rf, j)->id == w->topic_id) tn = recfile_topic(rf, j)->name;
      fprintf(stderr,
              "recinfo: %s: topic %s, writer %lld: source timestamp decreased %llu time(s), first at sample %lld\n",
              path, tn, (long long)w->writer_id, (unsigned long long)w->decreases, (long long)w->first_bad_id);
    }
    if (bad_writers) {
      printf("monotonic: FAILED (%llu writer(s))\n", (unsigned long long)bad_writers);
      if (status == EXIT_OK) status = EXIT_NOT_MONOTONIC;
    } else {
      printf("monotonic: ok (%zu writers)\n", ctx.nwriters);
    }
  }
  free(ctx.topics);
  free(ctx.writers);
  recfile_close(rf);
  return status;
}
