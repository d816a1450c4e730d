/* SPDX-License-Identifier: Apache-2.0 */
#include "replay_run.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <dds/dds.h>
#include <sqlite3.h>

#include "dds/vdds_config.h"
#include "dds/vdds_ident.h"
#include "recording/recfile.h"
#include "replay_pause.h"
#include "replay_topic.h"
#include "replay_write.h"
#include "verr.h"
#include "vsignal.h"

typedef struct replay {
  replay_options_t o; /* domain and partition filled from the recording where not given */
  bool pause_at_done;
  rpause_t pause;
  recfile_t *rf;
  sqlite3 *db;
  rp_topic_t *topics;
  size_t ntopics;
  dds_entity_t pp, pub;
  int64_t t0, t_end;
  /* The recording's own span (find_time_range): a source timestamp outside
   * [span_lo, span_hi] is garbled and never moves the schedule. */
  int64_t span_lo, span_hi;
  /* per pass */
  int64_t start_mono, sched_ts, last_progress;
  uint64_t pass_rows;
  uint64_t total_written, total_bad, total_skipped, total_out_of_span;
  rp_buf_t buf; /* rp_topic_write's scratch copy */
} replay_t;

static volatile sig_atomic_t stop_flag = 0;
static void on_signal(int sig) {
  (void)sig;
  stop_flag = 1;
}

/* SIGUSR1 requests (a counter, so two quick signals toggle twice). */
static volatile sig_atomic_t toggle_requests = 0;
static void on_usr1(int sig) {
  (void)sig;
  toggle_requests++;
}

static int64_t mono_ns(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static rp_topic_t *topic_by_id(replay_t *r, int64_t id) {
  for (size_t i = 0; i < r->ntopics; i++)
    if (r->topics[i].id == id) return &r->topics[i];
  return NULL;
}

static void progress(replay_t *r, bool force) {
  int64_t now = mono_ns();
  if (r->o.quiet || (!force && now - r->last_progress < DDS_SECS(1))) return;
  r->last_progress = now;
  double sim = (double)(r->sched_ts - r->t0) / 1e9;
  double total = r->t_end > r->t0 ? (double)(r->t_end - r->t0) / 1e9 : 0.0;
  fprintf(stderr, "replay: %llu samples written, sim time %.1f / %.1f s%s\n", (unsigned long long)r->total_written,
          sim < 0 ? 0.0 : sim, total, r->pause.paused ? " (paused)" : "");
}

static void set_paused(replay_t *r, bool paused, const char *why) {
  if (paused == r->pause.paused) return;
  int64_t now = mono_ns();
  int64_t was = r->pause.since;
  rpause_set(&r->pause, paused, now);
  if (r->o.quiet) return;
  double sim = (double)(r->sched_ts - r->t0) / 1e9;
  if (paused)
    fprintf(stderr, "replay: paused at sim time %.1f s (%s)\n", sim < 0 ? 0.0 : sim, why);
  else
    fprintf(stderr, "replay: resumed after %.1f s paused (%s)\n", (double)(now - was) / 1e9, why);
}

/* Applies the SIGUSR1 toggles received since the last call. */
static void handle_toggles(replay_t *r) {
  static sig_atomic_t seen = 0;
  while (seen != toggle_requests) {
    seen++;
    set_paused(r, !r->pause.paused, "SIGUSR1");
  }
}

/* Sleeps until the schedule time `base_due` (monotonic, before pause
 * shifts) in short steps so SIGINT and SIGUSR1 stay responsive; while
 * paused it waits for the resume. Returns false when interrupted. */
static bool sleep_until(replay_t *r, int64_t base_due) {
  for (;;) {
    if (stop_flag) return false;
    handle_toggles(r);
    int64_t now = mono_ns();
    int64_t deadline = rpause_due(&r->pause, base_due);
    if (now >= deadline) return true;
    int64_t d = deadline - now;
    if (d > DDS_MSECS(100)) d = DDS_MSECS(100);
    struct timespec ts = {.tv_sec = (time_t)(d / 1000000000), .tv_nsec = (long)(d % 1000000000)};
    nanosleep(&ts, NULL);
    progress(r, false);
  }
}

static int on_row(void *arg, const recfile_row_t *row) {
  replay_t *r = arg;
  if (stop_flag) return 1;
  rp_topic_t *t = topic_by_id(r, row->topic_id);
  r->pass_rows++;
  if (!t) {
    r->total_skipped++;
    return 0;
  }
  /* Only data rows are guaranteed monotonic (recording.h): the schedule
   * never goes backwards; rows older than the session start go at once. */
  int64_t ts = row->source_ts_ns;
  if (ts < r->span_lo || ts > r->span_hi) {
    /* INT64_MAX would have made the replay wait for ever: the sample goes
     * out at the current schedule time, counted. */
    if (r->total_out_of_span++ == 0)
      fprintf(stderr,
              "replay: %s: sample %lld: source time %lld ns outside the recording's span; sent without "
              "waiting\n",
              r->o.path, (long long)row->id, (long long)ts);
  } else if (ts > r->sched_ts) {
    r->sched_ts = ts;
  }
  int64_t rel = r->sched_ts - r->t0;
  int64_t seek_ns = (int64_t)(r->o.seek * 1e9);
  if (rel < seek_ns) {
    /* Skipped time: state (transient-local) topics are still written so
     * receivers start from the right state; streams are dropped. */
    if (!t->transient_local) {
      r->total_skipped++;
      return 0;
    }
  } else {
    int64_t pause_ns = (int64_t)(r->o.pause_at * 1e9);
    if (r->o.pause_at >= 0 && !r->pause_at_done && rel >= pause_ns) {
      /* Pause exactly at recording time S, not at the next sample's. */
      r->pause_at_done = true;
      int64_t at = pause_ns > seek_ns ? pause_ns : seek_ns;
      if (!sleep_until(r, r->start_mono + (int64_t)((double)(at - seek_ns) / r->o.speed))) return 1;
      set_paused(r, true, "--pause-at");
      progress(r, true);
    }
    int64_t due = r->start_mono + (int64_t)((double)(rel - seek_ns) / r->o.speed);
    if (!sleep_until(r, due)) return 1;
  }
  if (rp_topic_write(t, row, &r->buf)) {
    t->written++;
    r->total_written++;
  } else {
    t->bad++;
    r->total_bad++;
  }
  progress(r, false);
  return 0;
}

/* A recording spans at most this long (s): a damaged end time cannot make
 * the replay wait longer. */
#define REPLAY_MAX_SPAN_S (7 * 24 * 3600)

static int64_t query_i64(sqlite3 *db, const char *sql, int64_t lo, int64_t hi, int64_t dflt) {
  sqlite3_stmt *st = NULL;
  int64_t v = dflt;
  if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) == SQLITE_OK) {
    sqlite3_bind_int64(st, 1, lo);
    sqlite3_bind_int64(st, 2, hi);
    if (sqlite3_step(st) == SQLITE_ROW && sqlite3_column_type(st, 0) != SQLITE_NULL) v = sqlite3_column_int64(st, 0);
  }
  sqlite3_finalize(st);
  return v;
}

/* The recording's own span from the recorder's clock (the session row's
 * start and end, else the samples' receive times, at most
 * REPLAY_MAX_SPAN_S), widened by an hour before (keyframes a late joiner
 * took) and a minute after (writers' clocks). Sim time 0 is the session
 * start, or the first data sample inside the span. */
static void find_time_range(replay_t *r) {
  const recfile_session_t *s = recfile_session(r->rf);
  const int64_t big = INT64_MAX / 4;
  int64_t lo = s->valid && s->start_wall_ns > 0 ? s->start_wall_ns
                                                : query_i64(r->db,
                                                            "SELECT min(recv_wall_ns) FROM samples WHERE "
                                                            "recv_wall_ns BETWEEN ?1 AND ?2",
                                                            1, big, 1);
  int64_t hi = s->valid && s->has_end && s->end_wall_ns >= lo ? s->end_wall_ns
                                                              : query_i64(r->db,
                                                                          "SELECT max(recv_wall_ns) FROM samples "
                                                                          "WHERE recv_wall_ns BETWEEN ?1 AND ?2",
                                                                          lo, big, lo);
  if (hi - lo > DDS_SECS(REPLAY_MAX_SPAN_S)) hi = lo + DDS_SECS(REPLAY_MAX_SPAN_S);
  r->span_lo = lo > DDS_SECS(3600) ? lo - DDS_SECS(3600) : 1;
  r->span_hi = hi + DDS_SECS(60);
  const char *q = "SELECT %s(source_ts_ns) FROM samples WHERE kind = 0 AND source_ts_ns BETWEEN ?1 AND ?2";
  char sql[160];
  snprintf(sql, sizeof sql, q, "min");
  int64_t first = query_i64(r->db, sql, r->span_lo, r->span_hi, 0);
  snprintf(sql, sizeof sql, q, "max");
  int64_t last = query_i64(r->db, sql, r->span_lo, r->span_hi, 0);
  /* Sim time 0 is the session start (keyframes taken as a late joiner are
   * older and go out at once); without a session row, the first sample. */
  r->t0 = s->valid && s->start_wall_ns > 0 ? s->start_wall_ns : first;
  if (first > 0 && (r->t0 <= 0 || first > r->t0 + DDS_SECS(3600))) r->t0 = first;
  if (r->t0 <= 0) r->t0 = r->span_lo;
  r->t_end = last;
}

/* Opens the recording (and a second read-only connection for the
 * descriptor columns recfile does not expose) and fills in the recorded
 * domain and partition where none was given. Returns 0, or 1 after a
 * message. */
static int open_recording(replay_t *r) {
  verr_t err;
  if (recfile_open(&r->rf, r->o.path, &err) < 0) {
    fprintf(stderr, "replay: %s\n", err.msg);
    return 1;
  }
  const char *w = recfile_warnings(r->rf);
  if (*w) fprintf(stderr, "replay: %s: %s\n", r->o.path, w);
  if (recfile_damaged(r->rf)) fprintf(stderr, "replay: %s: damaged; replaying what can be read\n", r->o.path);
  /* A second read-only connection for the descriptor columns recfile does
   * not expose. */
  if (sqlite3_open_v2(r->o.path, &r->db, SQLITE_OPEN_READONLY, NULL) != SQLITE_OK) {
    fprintf(stderr, "replay: %s: cannot open: %s\n", r->o.path, r->db ? sqlite3_errmsg(r->db) : "?");
    sqlite3_close(r->db);
    recfile_close(r->rf);
    return 1;
  }
  sqlite3_busy_timeout(r->db, 2000);
  if (recfile_damaged(r->rf)) sqlite3_exec(r->db, "PRAGMA writable_schema=ON", NULL, NULL, NULL);
  const recfile_session_t *s = recfile_session(r->rf);
  if (r->o.domain < 0) r->o.domain = s->valid ? s->domain : 0;
  if (!r->o.partition[0]) {
    if (!s->valid || strpbrk(s->partition, "*?[") != NULL) {
      fprintf(stderr, "replay: %s: recorded partition '%s' is a pattern or unknown; give --partition\n", r->o.path,
              s->valid ? s->partition : "");
      sqlite3_close(r->db);
      recfile_close(r->rf);
      return 1;
    }
    snprintf(r->o.partition, sizeof r->o.partition, "%s", s->partition);
  }
  return 0;
}

/* Publishes the recording (every pass with --loop) and prints the
 * summary. Returns the exit code. */
static int publish_all(replay_t *r) {
  verr_t err;
  int status = 0;
  rp_type_verdict_t *verdicts = NULL;
  size_t nverdicts = 0;
  /* The loopback configuration by default; off loopback, DDS Security or
   * an explicit --insecure (vdds_config.h). */
  if (vdds_config_prepare(stderr, "replay", &err)) {
    fprintf(stderr, "replay: %s\n", err.msg);
    status = 1;
    goto out;
  }
  /* Before the participant: the check forks (replay_topic.h). */
  if (rp_types_precheck(r->db, r->o.path, &verdicts, &nverdicts, &err) < 0) {
    fprintf(stderr, "replay: %s\n", err.msg);
    status = 1;
    goto out;
  }
  dds_qos_t *ppq = vdds_participant_qos();
  r->pp = dds_create_participant((dds_domainid_t)r->o.domain, ppq, NULL);
  if (ppq) dds_delete_qos(ppq);
  if (r->pp < 0) {
    fprintf(stderr, "replay: cannot create a participant on domain %d: %s\n", r->o.domain, dds_strretcode(r->pp));
    status = 1;
    goto out;
  }
  dds_qos_t *pq = dds_create_qos();
  dds_qset_partition1(pq, r->o.partition);
  r->pub = dds_create_publisher(r->pp, pq, NULL);
  dds_delete_qos(pq);
  if (r->pub < 0) {
    fprintf(stderr, "replay: cannot create a publisher: %s\n", dds_strretcode(r->pub));
    status = 1;
    goto out;
  }
  size_t refused = 0;
  rp_setup_t su = {.db = r->db,
                   .path = r->o.path,
                   .pp = r->pp,
                   .pub = r->pub,
                   .speed = r->o.speed,
                   .refused = &refused,
                   .verdicts = verdicts,
                   .nverdicts = nverdicts};
  if (rp_topics_setup(&su, &r->topics, &r->ntopics, &err) < 0) {
    fprintf(stderr, "replay: %s\n", err.msg);
    status = 1;
    goto out;
  }
  find_time_range(r);
  /* A time past the last sample is allowed (nothing else to play), but the
   * user asked for something this recording does not have: say so. */
  double span_s = r->t_end > r->t0 ? (double)(r->t_end - r->t0) / 1e9 : 0.0;
  if (r->o.seek > span_s)
    fprintf(stderr,
            "replay: %s: --seek %g s is past the recording's last sample (%.3f s): only its state "
            "(transient-local) topics are written\n",
            r->o.path, r->o.seek, span_s);
  if (r->o.pause_at > span_s)
    fprintf(stderr, "replay: %s: --pause-at %g s is past the recording's last sample (%.3f s): it will not pause\n",
            r->o.path, r->o.pause_at, span_s);
  vsignal_on_stop(on_signal, 0);
  vsignal_on(SIGUSR1, on_usr1, SA_RESTART);
  if (!r->o.quiet)
    fprintf(stderr, "replay: %s: %zu topics into domain %d partition '%s' at speed %g\n", r->o.path, r->ntopics,
            r->o.domain, r->o.partition, r->o.speed);
  /* Let already running receivers match the new writers before the first
   * sample (volatile topics would otherwise lose it). */
  /* (a SIGUSR1 during this wait pauses before the first sample) */
  sleep_until(r, mono_ns() + DDS_MSECS(500));
  unsigned passes = 0;
  recfile_scan_report_t rep;
  memset(&rep, 0, sizeof rep);
  do {
    r->start_mono = mono_ns();
    rpause_new_pass(&r->pause, r->start_mono);
    r->sched_ts = r->t0;
    r->pass_rows = 0;
    recfile_scan(r->rf, 0, true, on_row, r, &rep);
    passes++;
    if (rep.damaged && passes == 1)
      fprintf(stderr, "replay: %s: damaged sample table: %s%s; %llu samples read\n", r->o.path, rep.first_error,
              rep.gave_up ? " (gave up past it)" : "", (unsigned long long)rep.rows);
    if (r->pass_rows == 0) break;
  } while (r->o.loop && !stop_flag);
  progress(r, true);
  /* Reliable receivers get everything written before the writers go. */
  for (size_t i = 0; i < r->ntopics; i++) dds_wait_for_acks(r->topics[i].writer, DDS_SECS(2));
  for (size_t i = 0; i < r->ntopics; i++)
    if (r->topics[i].bad)
      fprintf(stderr, "replay: %s: %llu samples could not be decoded with the stored type, skipped\n",
              r->topics[i].name, (unsigned long long)r->topics[i].bad);
  fprintf(stderr, "replay: %s %llu samples of %zu topics (%llu skipped, %llu undecodable)%s\n",
          stop_flag ? "interrupted after" : "wrote", (unsigned long long)r->total_written, r->ntopics,
          (unsigned long long)r->total_skipped, (unsigned long long)r->total_bad,
          passes > 1 ? " over several passes" : "");
  if (r->total_out_of_span)
    fprintf(stderr, "replay: %llu sample(s) with a source time outside the recording's span sent without waiting\n",
            (unsigned long long)r->total_out_of_span);
  printf("SUMMARY written=%llu topics=%zu bad=%llu skipped=%llu\n", (unsigned long long)r->total_written, r->ntopics,
         (unsigned long long)r->total_bad, (unsigned long long)r->total_skipped);
  /* Damage never stops a replay (what is readable goes out), but it is
   * never a success either: the caller learns the recording is damaged. */
  if (refused || r->total_bad || r->total_out_of_span || rep.damaged) {
    fprintf(stderr,
            "replay: %s is damaged (%zu topic(s) not replayed, %llu undecodable sample(s), %llu outside its span%s): "
            "what was readable was replayed; exit 1\n",
            r->o.path, refused, (unsigned long long)r->total_bad, (unsigned long long)r->total_out_of_span,
            rep.damaged ? ", a damaged sample table" : "");
    status = 1;
  }
out:
  free(verdicts);
  if (r->pp > 0) dds_delete(r->pp);
  for (size_t i = 0; i < r->ntopics; i++) rp_topic_free(&r->topics[i]);
  free(r->topics);
  free(r->buf.p);
  sqlite3_close(r->db);
  recfile_close(r->rf);
  return status;
}

int replay_run(const replay_options_t *o) {
  static replay_t r;
  r.o = *o;
  if (open_recording(&r)) return 1;
  return publish_all(&r);
}
