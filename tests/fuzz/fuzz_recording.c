/* SPDX-License-Identifier: Apache-2.0 */
/* fuzz_recording: damaged recordings against every reader of the format
 * (fuzz_files.h; issue 15 items 4 and 5): recfile (open, scan),
 * rec_decode (every product topic, as the report reads it), the resim
 * loader, and replay's topic setup and sample forwarding (replay_topic.h,
 * replay_write.h) on a real participant of $VISCERA_DOMAIN (loopback).
 *
 * Seeds: tests/fuzz/corpus/recording/base.db (a real session, trimmed to
 * 12 samples a topic) and recipes *.sql applied to it (the damage the
 * issue found: NULL or cut type mappings, damaged programs, INT64 times,
 * unknown versions). A round copies base.db, applies a recipe (every
 * recipe once, then at random), then 1-3 random edits (a stored sample's
 * bytes mutated, extreme or NULL cells in samples/topics/topic_keys/
 * session, rows deleted) and sometimes a byte of a file page flipped or the
 * file cut. The edits are logged as SQL next to the round's file (.sql):
 * a failing round's recipe goes into the corpus as it is. Contracts: no
 * crash, no sanitizer report, nothing runs away (ctest's timeout is the
 * backstop); a refusal has a message; resim never plans beyond
 * RESIM_MAX_SIM_S. */
#include <inttypes.h>
#include <stdarg.h>
#include <unistd.h>

#include <dds/dds.h>
#include <sqlite3.h>

#include "fuzz_files.h"
#include "recording/rec_decode.h"
#include "recording/recfile.h"
#include "replay_topic.h"
#include "replay_write.h"
#include "resim/resim_recording.h"
#include "viscera.h"

static const int64_t extremes[] = {INT64_MAX,    INT64_MIN,        0,        -1, 1, 4294967295LL, 4294967296LL,
                                   2147483647LL, 17593869044416LL, 1LL << 52};

typedef struct logbuf {
  char *p;
  size_t n, cap;
} logbuf_t;

static void logf_(logbuf_t *l, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void logf_(logbuf_t *l, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  int w = vsnprintf(NULL, 0, fmt, ap);
  va_end(ap);
  if (w < 0 || l->n + (size_t)w + 1 > l->cap) {
    size_t cap = (l->n + (size_t)w + 1) * 2;
    char *p = realloc(l->p, cap);
    if (!p) return;
    l->p = p;
    l->cap = cap;
  }
  va_start(ap, fmt);
  vsnprintf(l->p + l->n, l->cap - l->n, fmt, ap);
  va_end(ap);
  l->n += (size_t)w;
}

static void exec_logged(sqlite3 *db, logbuf_t *l, const char *sql) {
  logf_(l, "%s;\n", sql);
  sqlite3_exec(db, sql, NULL, NULL, NULL); /* a constraint may refuse it: fine */
}

/* A blob cell mutated in place (read, fuzz_mutate, written back as x'..'). */
static void mutate_blob(sqlite3 *db, logbuf_t *l, uint64_t *s, const char *table, const char *col, const char *where) {
  char sql[512];
  snprintf(sql, sizeof sql, "SELECT %s FROM %s WHERE %s", col, table, where);
  sqlite3_stmt *st = NULL;
  fuzz_buf_t b = {0};
  if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW) {
    int n = sqlite3_column_bytes(st, 0);
    if (n > 0 && n < FUZZ_MAX_INPUT && !fuzz_buf_reserve(&b, (size_t)n + 1)) {
      memcpy(b.p, sqlite3_column_blob(st, 0), (size_t)n);
      b.n = (size_t)n;
      b.p[b.n] = 0;
    }
  }
  sqlite3_finalize(st);
  if (b.n) {
    fuzz_mutate(&b, s, NULL, 0);
    char *hex = malloc(2 * b.n + 1);
    char *q = malloc(2 * b.n + 512);
    if (hex && q) {
      for (size_t i = 0; i < b.n; i++) snprintf(hex + 2 * i, 3, "%02x", b.p[i]);
      hex[2 * b.n] = 0;
      snprintf(q, 2 * b.n + 512, "UPDATE %s SET %s = x'%s' WHERE %s", table, col, hex, where);
      exec_logged(db, l, q);
    }
    free(hex);
    free(q);
  }
  free(b.p);
}

static void random_edit(sqlite3 *db, logbuf_t *l, uint64_t *s) {
  char where[128], sql[512];
  int64_t x = extremes[fuzz_below(s, sizeof extremes / sizeof *extremes)];
  snprintf(where, sizeof where, "id = (SELECT id FROM samples ORDER BY id LIMIT 1 OFFSET %zu)", fuzz_below(s, 64));
  static const char *const tcols[] = {"ops", "typeinfo", "typemap"};
  static const char *const ncols[] = {"desc_size",     "desc_align", "desc_flagset",
                                      "nkeys",         "nops",       "restrict_data_representation",
                                      "history_depth", "deadline_ns"};
  static const char *const scols[] = {"format_version", "start_wall_ns", "end_wall_ns", "domain"};
  char twhere[64];
  snprintf(twhere, sizeof twhere, "id = %zu", 1 + fuzz_below(s, 10));
  switch (fuzz_below(s, 10)) {
  case 0:
  case 1:
    mutate_blob(db, l, s, "samples", "cdr", where);
    return;
  case 2:
    snprintf(sql, sizeof sql, "UPDATE samples SET %s = %" PRId64 " WHERE %s",
             fuzz_below(s, 2) ? "source_ts_ns" : "recv_wall_ns", x, where);
    break;
  case 3:
    snprintf(sql, sizeof sql, "UPDATE samples SET %s = %" PRId64 " WHERE %s",
             fuzz_below(s, 2) ? "kind" : (fuzz_below(s, 2) ? "topic_id" : "writer_id"),
             fuzz_below(s, 2) ? (int64_t)fuzz_below(s, 12) - 1 : x, where);
    break;
  case 4: {
    const char *col = tcols[fuzz_below(s, 3)];
    if (fuzz_below(s, 2)) {
      mutate_blob(db, l, s, "topics", col, twhere);
      return;
    }
    switch (fuzz_below(s, 3)) {
    case 0:
      snprintf(sql, sizeof sql, "UPDATE topics SET %s = NULL WHERE %s", col, twhere);
      break;
    case 1:
      snprintf(sql, sizeof sql, "UPDATE topics SET %s = zeroblob(length(%s)) WHERE %s", col, col, twhere);
      break;
    default:
      snprintf(sql, sizeof sql, "UPDATE topics SET %s = (SELECT %s FROM topics WHERE id = %zu) WHERE %s", col, col,
               1 + fuzz_below(s, 10), twhere);
    }
    break;
  }
  case 5:
    snprintf(sql, sizeof sql, "UPDATE topics SET %s = %" PRId64 " WHERE %s", ncols[fuzz_below(s, 8)], x, twhere);
    break;
  case 6:
    if (fuzz_below(s, 3) == 0)
      snprintf(sql, sizeof sql, "DELETE FROM topic_keys WHERE topic_id = %zu", 1 + fuzz_below(s, 10));
    else
      snprintf(sql, sizeof sql, "UPDATE topic_keys SET %s = %" PRId64 " WHERE topic_id = %zu",
               fuzz_below(s, 2) ? "offset" : "key_index", fuzz_below(s, 2) ? x : (int64_t)fuzz_below(s, 40),
               1 + fuzz_below(s, 10));
    break;
  case 7:
    if (fuzz_below(s, 4) == 0)
      snprintf(sql, sizeof sql, "DELETE FROM session");
    else
      snprintf(sql, sizeof sql, "UPDATE session SET %s = %" PRId64, scols[fuzz_below(s, 4)],
               fuzz_below(s, 2) ? x : (int64_t)fuzz_below(s, 4));
    break;
  case 8:
    snprintf(sql, sizeof sql, "DELETE FROM %s WHERE %s", fuzz_below(s, 3) ? "samples" : "topics",
             fuzz_below(s, 2) ? where : twhere);
    break;
  default:
    snprintf(sql, sizeof sql, "PRAGMA user_version = %zu", fuzz_below(s, 3));
  }
  exec_logged(db, l, sql);
}

static int nop_cb(void *arg, const void *sample, const recfile_row_t *row) {
  (void)sample;
  (void)row;
  (*(uint64_t *)arg)++;
  return 0;
}

typedef struct rp_ctx {
  rp_topic_t *topics;
  size_t ntopics;
  rp_buf_t buf;
  uint64_t written, bad;
} rp_ctx_t;

static int write_cb(void *arg, const recfile_row_t *row) {
  rp_ctx_t *c = arg;
  for (size_t i = 0; i < c->ntopics; i++)
    if (c->topics[i].id == row->topic_id) {
      if (rp_topic_write(&c->topics[i], row, &c->buf))
        c->written++;
      else
        c->bad++;
    }
  return 0;
}

static const struct {
  const char *name;
  const dds_topic_descriptor_t *desc;
} product[] = {{"viscera_SceneInfo", &viscera_SceneInfo_desc},
               {"viscera_MeshState", &viscera_MeshState_desc},
               {"viscera_MeshDelta", &viscera_MeshDelta_desc},
               {"viscera_ToolCommand", &viscera_ToolCommand_desc},
               {"viscera_ContactFeedback", &viscera_ContactFeedback_desc},
               {"viscera_SessionEvent", &viscera_SessionEvent_desc},
               {"viscera_Metrics", &viscera_Metrics_desc}};

/* Every reader on the file at `path`. NULL, or a broken contract. */
static const char *run_readers(const char *path, dds_entity_t pp, dds_entity_t pub, uint64_t *decoded,
                               uint64_t *replayed) {
  verr_t e;
  recfile_t *rf = NULL;
  if (recfile_open(&rf, path, &e) == 0) {
    recfile_scan_report_t rep;
    uint64_t n = 0;
    recfile_scan(rf, 0, true, (recfile_row_cb)(void (*)(void))nop_cb, &n, &rep);
    for (size_t i = 0; i < sizeof product / sizeof *product; i++) {
      rec_decode_report_t dr;
      rec_decode_topic(rf, product[i].name, product[i].desc, nop_cb, decoded, &dr);
    }
    /* Replay: the stored descriptors into Cyclone, every row out again. */
    sqlite3 *db = NULL;
    if (sqlite3_open_v2(path, &db, SQLITE_OPEN_READONLY, NULL) == SQLITE_OK) {
      rp_ctx_t c = {0};
      rp_setup_t su = {.db = db, .path = path, .pp = pp, .pub = pub, .speed = 1};
      if (rp_topics_setup(&su, &c.topics, &c.ntopics, &e) == 0)
        recfile_scan(rf, 0, true, write_cb, &c, &rep);
      else if (!e.msg[0]) {
        sqlite3_close(db);
        recfile_close(rf);
        return "replay refused without a message";
      }
      for (size_t i = 0; i < c.ntopics; i++) {
        if (c.topics[i].writer > 0) dds_delete(c.topics[i].writer);
        if (c.topics[i].topic > 0) dds_delete(c.topics[i].topic);
        rp_topic_free(&c.topics[i]);
      }
      free(c.topics);
      free(c.buf.p);
      *replayed += c.written;
    }
    sqlite3_close(db);
    recfile_close(rf);
  } else if (!e.msg[0]) {
    return "recfile refused without a message";
  }
  static resim_recording_t rec;
  if (resim_recording_load(&rec, path, NULL, 0, &e) == 0) {
    int bad = rec.dt > 0 && (double)rec.last_step * rec.dt > RESIM_MAX_SIM_S + 1;
    resim_recording_free(&rec);
    if (bad) return "resim planned beyond RESIM_MAX_SIM_S";
  } else if (!e.msg[0]) {
    return "resim refused without a message";
  }
  return NULL;
}

int main(int argc, char **argv) {
  fuzz_run_t r = {0};
  if (fuzz_args(&r, "fuzz_recording", argc, argv)) return 2;
  char path[1024];
  snprintf(path, sizeof path, "%s/base.db", r.corpus_dir);
  fuzz_buf_t base = {0};
  if (fuzz_read_file(path, &base)) {
    fprintf(stderr, "fuzz_recording: cannot read %s\n", path);
    return 1;
  }
  fuzz_corpus_t recipes;
  if (fuzz_corpus_load(&recipes, r.corpus_dir, ".sql")) recipes.n = 0;
  const char *dom = getenv("VISCERA_DOMAIN");
  dds_entity_t pp = dds_create_participant(dom ? (dds_domainid_t)atoi(dom) : 195, NULL, NULL);
  dds_qos_t *q = dds_create_qos();
  dds_qset_partition1(q, "hardinput/fuzz");
  dds_entity_t pub = pp > 0 ? dds_create_publisher(pp, q, NULL) : pp;
  dds_delete_qos(q);
  if (pp < 0 || pub < 0) {
    fprintf(stderr, "fuzz_recording: no DDS participant: %s\n", dds_strretcode(pp < 0 ? pp : pub));
    return 1;
  }
  int failed = 0;
  long rounds = 0;
  uint64_t decoded = 0, replayed = 0;
  double t0 = fuzz_now();
  logbuf_t log = {0};
  for (long i = -(long)recipes.n - 1; i < r.iterations; i++, rounds++) {
    if (fuzz_now() - t0 > r.cap_s) {
      printf("fuzz_recording: safety stop after %ld rounds (%.0f s cap)\n", rounds, r.cap_s);
      break;
    }
    uint64_t s = r.seed * 0x9e3779b97f4a7c15ull + (uint64_t)i;
    fuzz_pending(&r, i, ".db", base.p, base.n);
    log.n = 0;
    logf_(&log, "-- fuzz_recording seed %llu round %ld: applied to base.db\n", (unsigned long long)r.seed, i);
    sqlite3 *db = NULL;
    if (sqlite3_open(r.pending, &db) != SQLITE_OK) return 1;
    long recipe =
        i < -1 ? i + (long)recipes.n + 1 : (recipes.n && fuzz_below(&s, 2) ? (long)fuzz_below(&s, recipes.n) : -1);
    if (i < -1 || (i >= 0 && recipe >= 0)) {
      logf_(&log, "-- recipe %s\n", recipes.name[recipe]);
      exec_logged(db, &log, (const char *)recipes.data[recipe].p);
    }
    int edits = i < 0 ? 0 : 1 + (int)fuzz_below(&s, 3);
    for (int k = 0; k < edits; k++) random_edit(db, &log, &s);
    sqlite3_close(db);
    if (i >= 0 && fuzz_below(&s, 8) == 0) { /* a damaged page, or a cut file */
      FILE *f = fopen(r.pending, "r+b");
      if (f) {
        long at = 100 + (long)fuzz_below(&s, base.n - 100);
        if (fuzz_below(&s, 2)) {
          fseek(f, at, SEEK_SET);
          fputc((int)fuzz_below(&s, 256), f);
          logf_(&log, "-- and byte %ld of the file overwritten (not expressible in SQL)\n", at);
        } else {
          if (ftruncate(fileno(f), at) == 0) logf_(&log, "-- and the file cut at %ld bytes\n", at);
        }
        fclose(f);
      }
    }
    char sqlpath[1100];
    snprintf(sqlpath, sizeof sqlpath, "%s.sql", r.pending);
    fuzz_write_file(sqlpath, log.p, log.n);
    const char *why = run_readers(r.pending, pp, pub, &decoded, &replayed);
    if (why) {
      fuzz_failed(&r, i, why);
      failed++;
    } else {
      fuzz_passed(&r);
      remove(sqlpath);
    }
  }
  printf("fuzz_recording: %ld rounds (%zu recipes), %" PRIu64 " samples decoded, %" PRIu64 " replayed, %d failed\n",
         rounds, recipes.n, decoded, replayed, failed);
  dds_delete(pp);
  free(log.p);
  free(base.p);
  fuzz_corpus_free(&recipes);
  return failed ? 1 : 0;
}
