/* SPDX-License-Identifier: Apache-2.0 */
#include "recording/recfile.h"
#include "dds/vdds_ident.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <sqlite3.h>

#include "recording/recording.h"

struct recfile {
  sqlite3 *db;
  char *path;
  recfile_session_t session;
  recfile_topic_t *topics;
  size_t ntopics;
  bool damaged;
  char warnings[512];
};

static void warn(recfile_t *rf, const char *fmt, const char *detail) {
  size_t len = strlen(rf->warnings);
  if (len + 2 >= sizeof rf->warnings) return;
  if (len) rf->warnings[len++] = '\n', rf->warnings[len] = 0;
  snprintf(rf->warnings + len, sizeof rf->warnings - len, fmt, detail);
}

static void copy_text(char *dst, size_t size, sqlite3_stmt *st, int col) {
  const unsigned char *t = sqlite3_column_text(st, col);
  snprintf(dst, size, "%s", t ? (const char *)t : "");
}

/* A file that is not a database at all gets a plain answer before SQLite is
 * involved, so the message does not depend on SQLite's wording. */
static int check_file(const char *path, bool *wal_mode, verr_t *err) {
  struct stat sb;
  if (stat(path, &sb) != 0) return verr_set(err, "%s: %s", path, strerror(errno));
  if (S_ISDIR(sb.st_mode)) return verr_set(err, "%s: is a directory, not a recording", path);
  if (sb.st_size == 0) return verr_set(err, "%s: empty file, not a recording", path);
  FILE *f = fopen(path, "rb");
  if (!f) return verr_set(err, "%s: %s", path, strerror(errno));
  unsigned char hdr[20] = {0};
  size_t n = fread(hdr, 1, sizeof hdr, f);
  fclose(f);
  if (n < 16 || memcmp(hdr, "SQLite format 3", 16) != 0)
    return verr_set(err, "%s: not a SQLite database, so not a viscera recording", path);
  /* Header bytes 18-19 (write and read format versions) are 2 in WAL mode. */
  *wal_mode = n == sizeof hdr && hdr[18] == 2 && hdr[19] == 2;
  return 0;
}

/* A WAL-mode database with no table at all is what a recorder leaves in its
 * main file while it runs or after kill -9: schema and samples wait in
 * PATH-wal until the WAL is checkpointed (at a clean stop, or every few MB).
 * Copied without that file it reads as empty; say so rather than "not a
 * recording", since the fix is to bring the -wal file along. */
static bool wal_left_behind(const char *path, bool wal_mode, int ntables) {
  if (!wal_mode || ntables != 0) return false;
  char wal[PATH_MAX + 8];
  snprintf(wal, sizeof wal, "%s-wal", path);
  struct stat sb;
  return stat(wal, &sb) != 0 || sb.st_size == 0;
}

static int pragma_int(sqlite3 *db, const char *sql, int64_t *v) {
  sqlite3_stmt *st = NULL;
  int rc = sqlite3_prepare_v2(db, sql, -1, &st, NULL);
  if (rc == SQLITE_OK) {
    rc = sqlite3_step(st);
    if (rc == SQLITE_ROW) {
      *v = sqlite3_column_int64(st, 0);
      rc = SQLITE_OK;
    }
  }
  sqlite3_finalize(st);
  return rc;
}

static const char *db_reason(sqlite3 *db, int rc) {
  int base = rc & 0xff;
  if (base == SQLITE_NOTADB) return "not a SQLite database, so not a viscera recording";
  if (base == SQLITE_CORRUPT) return "damaged (SQLite: database disk image is malformed)";
  return sqlite3_errmsg(db);
}

/* Reads the identification and which required tables exist; the SQLite
 * code of the first failure otherwise. */
static int load_schema(sqlite3 *db, int64_t *app_id, bool have[REC_REQUIRED_TABLE_COUNT], int *ntables) {
  static const char *required[] = REC_REQUIRED_TABLES;
  int rc = pragma_int(db, "PRAGMA application_id", app_id);
  if (rc != SQLITE_OK) return rc;
  sqlite3_stmt *st = NULL;
  rc = sqlite3_prepare_v2(db, "SELECT name FROM sqlite_master WHERE type='table'", -1, &st, NULL);
  if (rc != SQLITE_OK) return rc;
  *ntables = 0;
  while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
    const char *name = (const char *)sqlite3_column_text(st, 0);
    (*ntables)++;
    for (int i = 0; name && i < REC_REQUIRED_TABLE_COUNT; i++)
      if (strcmp(name, required[i]) == 0) have[i] = true;
  }
  sqlite3_finalize(st);
  return rc == SQLITE_DONE ? SQLITE_OK : rc;
}

static void read_session(recfile_t *rf) {
  sqlite3_stmt *st = NULL;
  recfile_session_t *s = &rf->session;
  if (sqlite3_prepare_v2(rf->db,
                         "SELECT format_version, scene, partition, domain, start_wall_ns, end_wall_ns, hostname,"
                         " recorder_version, dds_version FROM session LIMIT 1",
                         -1, &st, NULL) != SQLITE_OK) {
    warn(rf, "session metadata unreadable: %s", sqlite3_errmsg(rf->db));
    return;
  }
  int rc = sqlite3_step(st);
  if (rc == SQLITE_ROW) {
    s->valid = true;
    s->format_version = sqlite3_column_int(st, 0);
    copy_text(s->scene, sizeof s->scene, st, 1);
    copy_text(s->partition, sizeof s->partition, st, 2);
    s->domain = sqlite3_column_int(st, 3);
    s->start_wall_ns = sqlite3_column_int64(st, 4);
    s->has_end = sqlite3_column_type(st, 5) != SQLITE_NULL;
    s->end_wall_ns = s->has_end ? sqlite3_column_int64(st, 5) : 0;
    copy_text(s->hostname, sizeof s->hostname, st, 6);
    copy_text(s->recorder_version, sizeof s->recorder_version, st, 7);
    copy_text(s->dds_version, sizeof s->dds_version, st, 8);
  } else if (rc == SQLITE_DONE) {
    warn(rf, "%s", "session metadata missing (empty session table)");
  } else {
    warn(rf, "session metadata unreadable: %s", db_reason(rf->db, rc));
    rf->damaged = true;
  }
  sqlite3_finalize(st);
}

static void read_topics(recfile_t *rf) {
  sqlite3_stmt *st = NULL;
  if (sqlite3_prepare_v2(rf->db,
                         "SELECT id, name, type_name, reliability, durability,"
                         " (SELECT count(*) FROM writers w WHERE w.topic_id = t.id) FROM topics t ORDER BY id",
                         -1, &st, NULL) != SQLITE_OK) {
    warn(rf, "topic table unreadable: %s", sqlite3_errmsg(rf->db));
    return;
  }
  int rc;
  while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
    recfile_topic_t *n = realloc(rf->topics, (rf->ntopics + 1) * sizeof *n);
    if (!n) break;
    rf->topics = n;
    recfile_topic_t *t = &rf->topics[rf->ntopics++];
    memset(t, 0, sizeof *t);
    t->id = sqlite3_column_int64(st, 0);
    copy_text(t->name, sizeof t->name, st, 1);
    copy_text(t->type_name, sizeof t->type_name, st, 2);
    copy_text(t->reliability, sizeof t->reliability, st, 3);
    copy_text(t->durability, sizeof t->durability, st, 4);
    t->writers = sqlite3_column_int64(st, 5);
  }
  if (rc != SQLITE_DONE) {
    warn(rf, "topic table partly unreadable: %s", db_reason(rf->db, rc));
    rf->damaged = true;
  }
  sqlite3_finalize(st);
}

int recfile_open(recfile_t **out, const char *path, verr_t *err) {
  *out = NULL;
  bool wal_mode = false;
  if (check_file(path, &wal_mode, err) < 0) return -1;
  recfile_t *rf = calloc(1, sizeof *rf);
  if (!rf || !(rf->path = strdup(path))) {
    free(rf);
    return verr_set(err, "%s: out of memory", path);
  }
  /* Read-only: inspecting a recording must never change it (a killed
   * recorder's WAL is read, not checkpointed). */
  int rc = sqlite3_open_v2(path, &rf->db, SQLITE_OPEN_READONLY, NULL);
  if (rc != SQLITE_OK) {
    verr_set(err, "%s: cannot open: %s", path, rf->db ? sqlite3_errmsg(rf->db) : sqlite3_errstr(rc));
    goto fail;
  }
  /* A damaged file must not make a query spin on a lock forever. */
  sqlite3_busy_timeout(rf->db, 2000);
  int64_t app_id = 0;
  bool have[REC_REQUIRED_TABLE_COUNT] = {false};
  int ntables = 0;
  rc = load_schema(rf->db, &app_id, have, &ntables);
  if ((rc & 0xff) == SQLITE_CORRUPT) {
    /* SQLite refuses a file shorter than its header says (a truncated
     * copy, a disk that filled up) unless the schema is "writable"; on a
     * read-only connection that only relaxes the check, and every page
     * that is still there can be read. */
    sqlite3_exec(rf->db, "PRAGMA writable_schema=ON", NULL, NULL, NULL);
    int rc2 = load_schema(rf->db, &app_id, have, &ntables);
    if (rc2 == SQLITE_OK) {
      rf->damaged = true;
      warn(rf, "%s", "truncated or damaged (SQLite: database disk image is malformed); reading what is left");
      rc = SQLITE_OK;
    }
  }
  if (rc != SQLITE_OK) {
    verr_set(err, "%s: %s", path, db_reason(rf->db, rc));
    goto fail;
  }
  if (wal_left_behind(path, wal_mode, ntables)) {
    verr_set(err,
             "%s: holds no tables yet: its content is in the write-ahead log %s-wal, which is missing (a recorder "
             "killed or still running keeps its samples there; copy that file beside this one)",
             path, path);
    goto fail;
  }
  static const char *required[] = REC_REQUIRED_TABLES;
  for (int i = 0; i < REC_REQUIRED_TABLE_COUNT; i++) {
    if (!have[i]) {
      if (app_id == REC_APPLICATION_ID)
        verr_set(err, "%s: damaged viscera recording: table '%s' is missing", path, required[i]);
      else
        verr_set(err, "%s: a SQLite database but not a viscera recording (no '%s' table)", path, required[i]);
      goto fail;
    }
  }
  int64_t user_version = 0;
  pragma_int(rf->db, "PRAGMA user_version", &user_version);
  if (app_id != REC_APPLICATION_ID) warn(rf, "%s", "identification pragma missing (file rewritten by another tool?)");
  /* A format this tool does not know is refused, not guessed at: its
   * tables may mean something else (0: the pragma was lost, see above). */
  if (user_version < 0 || user_version > REC_FORMAT_VERSION) {
    verr_set(err, "%s: recording format version %lld is not one this tool reads (1..%d)", path, (long long)user_version,
             REC_FORMAT_VERSION);
    goto fail;
  }
  read_session(rf);
  if (rf->session.valid && (rf->session.format_version < 1 || rf->session.format_version > REC_FORMAT_VERSION)) {
    verr_set(err, "%s: recording format version %d (session row) is not one this tool reads (1..%d)", path,
             rf->session.format_version, REC_FORMAT_VERSION);
    goto fail;
  }
  read_topics(rf);
  *out = rf;
  return 0;
fail:
  sqlite3_close(rf->db);
  free(rf->path);
  free(rf);
  return -1;
}

void recfile_close(recfile_t *rf) {
  if (!rf) return;
  sqlite3_close(rf->db);
  free(rf->topics);
  free(rf->path);
  free(rf);
}

const char *recfile_path(const recfile_t *rf) { return rf->path; }
const recfile_session_t *recfile_session(const recfile_t *rf) { return &rf->session; }
size_t recfile_topic_count(const recfile_t *rf) { return rf->ntopics; }
const recfile_topic_t *recfile_topic(const recfile_t *rf, size_t i) { return i < rf->ntopics ? &rf->topics[i] : NULL; }
const char *recfile_warnings(const recfile_t *rf) { return rf->warnings; }
bool recfile_damaged(const recfile_t *rf) { return rf->damaged; }

const recfile_topic_t *recfile_topic_by_name(const recfile_t *rf, const char *name) {
  for (size_t i = 0; i < rf->ntopics; i++)
    if (strcmp(rf->topics[i].name, name) == 0) return &rf->topics[i];
  return NULL;
}

static void note_damage(recfile_t *rf, recfile_scan_report_t *rep, int64_t near_id, int rc) {
  rep->damaged++;
  if (!rep->first_error[0])
    snprintf(rep->first_error, sizeof rep->first_error, "at sample id %lld: %s", (long long)near_id,
             db_reason(rf->db, rc));
}

/* Reads rows with id > after; returns the SQLite code that ended the scan
 * (SQLITE_DONE when complete) and advances *after past each row read. */
static int scan_from(recfile_t *rf, int64_t *after, int64_t topic_id, bool with_cdr, recfile_row_cb cb, void *arg,
                     recfile_scan_report_t *rep, bool *stopped) {
  char sql[256];
  /* NOT INDEXED: walk the table by rowid, never through samples_by_topic.
   * That index is built at close, so it sits at the end of the file: the
   * first thing a truncation loses, and a damaged index would hide rows
   * that are intact in the table. */
  snprintf(sql, sizeof sql,
           "SELECT id, topic_id, writer_id, source_ts_ns, recv_wall_ns, kind, inferred, length(cdr)%s"
           " FROM samples NOT INDEXED WHERE id > ?1%s ORDER BY id",
           with_cdr ? ", cdr" : "", topic_id > 0 ? " AND topic_id = ?2" : "");
  sqlite3_stmt *st = NULL;
  int rc = sqlite3_prepare_v2(rf->db, sql, -1, &st, NULL);
  if (rc != SQLITE_OK) return rc;
  sqlite3_bind_int64(st, 1, *after);
  if (topic_id > 0) sqlite3_bind_int64(st, 2, topic_id);
  while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
    recfile_row_t r;
    r.id = sqlite3_column_int64(st, 0);
    r.topic_id = sqlite3_column_int64(st, 1);
    r.writer_id = sqlite3_column_type(st, 2) == SQLITE_NULL ? 0 : sqlite3_column_int64(st, 2);
    r.source_ts_ns = sqlite3_column_int64(st, 3);
    r.recv_wall_ns = sqlite3_column_int64(st, 4);
    r.kind = sqlite3_column_int(st, 5);
    r.inferred = sqlite3_column_int(st, 6) != 0;
    int64_t len = sqlite3_column_int64(st, 7);
    r.cdr_len = len > 0 ? (size_t)len : 0;
    r.cdr = NULL;
    /* A garbled interior page can yield keys out of order; insertion order
     * is the contract, so such rows are not delivered (and cannot loop). */
    if (r.id <= *after) {
      rep->invalid++;
      continue;
    }
    if (with_cdr) {
      r.cdr = sqlite3_column_blob(st, 8);
      int n = sqlite3_column_bytes(st, 8);
      /* The blob can live on overflow pages that are damaged or cut off
       * while the row itself is fine: SQLite then returns no blob (or not
       * the length the record header announced). Lose that sample, keep
       * scanning. */
      if (len > 0 && (!r.cdr || (int64_t)n != len)) {
        note_damage(rf, rep, r.id, SQLITE_CORRUPT);
        *after = r.id;
        continue;
      }
      r.cdr_len = n > 0 ? (size_t)n : 0;
      if (!r.cdr) r.cdr_len = 0;
    }
    *after = r.id;
    if (r.topic_id < 1 || r.kind < REC_KIND_DATA || r.kind > REC_KIND_UNREGISTER || len < 0) {
      rep->invalid++;
      continue;
    }
    rep->rows++;
    if (cb(arg, &r)) {
      *stopped = true;
      rc = SQLITE_DONE;
      break;
    }
  }
  sqlite3_finalize(st);
  return rc;
}

void recfile_scan(recfile_t *rf, int64_t topic_id, bool with_cdr, recfile_row_cb cb, void *arg,
                  recfile_scan_report_t *rep) {
  memset(rep, 0, sizeof *rep);
  int64_t after = 0;
  bool stopped = false;
  /* On damage, resume further on: a truncated or overwritten b-tree page
   * loses the rows on it, not the rows after it. Jumps grow geometrically
   * so a damaged tail is given up on after a bounded number of tries. */
  int64_t jump = 1;
  for (int attempt = 0; attempt < 64; attempt++) {
    int64_t before = after;
    int rc = scan_from(rf, &after, topic_id, with_cdr, cb, arg, rep, &stopped);
    if (rc == SQLITE_DONE || stopped) return;
    note_damage(rf, rep, after + 1, rc);
    if ((rc & 0xff) == SQLITE_NOMEM || (rc & 0xff) == SQLITE_INTERRUPT) break;
    if (after > before)
      jump = 1; /* progress: restart small after the new damage */
    else
      jump = jump < ((int64_t)1 << 40) ? jump * 8 : jump;
    if (after > INT64_MAX - jump) break;
    after += jump;
  }
  rep->gave_up = true;
}

static void copy_clean(char *dst, size_t size, sqlite3_stmt *st, int col) {
  const void *t = sqlite3_column_blob(st, col);
  vdds_ident_sanitize(dst, size, t, t ? (size_t)sqlite3_column_bytes(st, col) : 0);
}

int recfile_participants(recfile_t *rf, recfile_participant_cb cb, void *arg) {
  sqlite3_stmt *st = NULL;
  int rc = sqlite3_prepare_v2(rf->db, "SELECT count(*) FROM sqlite_master WHERE type='table' AND name='participants'",
                              -1, &st, NULL);
  bool have = rc == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW && sqlite3_column_int(st, 0) > 0;
  sqlite3_finalize(st);
  if (!have) return -1;
  /* subject: a later column (recording.h); older files read it as NULL */
  bool subject = sqlite3_prepare_v2(rf->db, "SELECT subject FROM participants LIMIT 0", -1, &st, NULL) == SQLITE_OK;
  sqlite3_finalize(st);
  if (sqlite3_prepare_v2(rf->db,
                         subject ? "SELECT guid, user_data, role, first_seen_wall_ns, last_seen_wall_ns, left_wall_ns,"
                                   " subject FROM participants ORDER BY first_seen_wall_ns, guid"
                                 : "SELECT guid, user_data, role, first_seen_wall_ns, last_seen_wall_ns, left_wall_ns,"
                                   " NULL FROM participants ORDER BY first_seen_wall_ns, guid",
                         -1, &st, NULL) != SQLITE_OK) {
    sqlite3_finalize(st);
    return -2;
  }
  int n = 0;
  while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
    recfile_participant_t p;
    memset(&p, 0, sizeof p);
    copy_clean(p.guid, sizeof p.guid, st, 0);
    copy_clean(p.user_data, sizeof p.user_data, st, 1);
    copy_clean(p.role, sizeof p.role, st, 2);
    p.first_seen_wall_ns = sqlite3_column_int64(st, 3);
    p.last_seen_wall_ns = sqlite3_column_int64(st, 4);
    p.left_wall_ns = sqlite3_column_type(st, 5) == SQLITE_NULL ? -1 : sqlite3_column_int64(st, 5);
    copy_clean(p.subject, sizeof p.subject, st, 6);
    cb(arg, &p);
    n++;
  }
  sqlite3_finalize(st);
  return rc == SQLITE_DONE ? n : -2;
}

void *recfile_sqlite(recfile_t *rf) { return rf->db; }
