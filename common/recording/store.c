/* SPDX-License-Identifier: Apache-2.0 */
#include "recording/store.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <dds/ddsi/ddsi_cdrstream.h>
#include <dds/version.h>
#include <sqlite3.h>

#include "recording/recording.h"
#include "vtime.h"

struct store {
  sqlite3 *db;
  char *path;
  sqlite3_stmt *ins_sample;
  sqlite3_stmt *ins_topic;
  sqlite3_stmt *ins_key;
  sqlite3_stmt *ins_writer;
  sqlite3_stmt *ins_part, *left_part, *subj_part;
  store_batch_limits_t limits;
  bool in_txn;
  uint64_t batch_start_ns;
  uint32_t batch_samples;
  uint64_t batch_bytes;
  uint64_t total_samples;
  uint64_t total_bytes;
  /* What earlier batches put in the file for good (see write_failed). */
  uint64_t committed_samples;
  uint64_t committed_bytes;
  /* A write failed: the store is stopped, every later write returns
   * fail_msg; disk_full when the cause was a full disk or file-size limit. */
  bool failed;
  bool disk_full;
  char fail_msg[512];
};

static int db_fail(store_t *s, verr_t *err, const char *what) {
  return verr_set(err, "%s: %s: %s", s->path, what, sqlite3_errmsg(s->db));
}

/* Is there no room left for `path` or its WAL: the file system nearly
 * full (< 1 MB for an unprivileged writer) or either file at the process's
 * file-size limit (RLIMIT_FSIZE, ulimit -f)? */
static bool no_room(const char *path) {
  struct statvfs vfs;
  char dir[4096];
  snprintf(dir, sizeof dir, "%s", path);
  char *slash = strrchr(dir, '/');
  if (!slash)
    snprintf(dir, sizeof dir, ".");
  else if (slash == dir)
    dir[1] = 0; /* "/file": the root */
  else
    *slash = 0;
  if (statvfs(dir, &vfs) == 0 && (uint64_t)vfs.f_bavail * vfs.f_frsize < 1024u * 1024u) return true;
  struct rlimit rl;
  if (getrlimit(RLIMIT_FSIZE, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
    const char *suffix[] = {"", "-wal"};
    for (int i = 0; i < 2; i++) {
      char f[4096];
      struct stat sb;
      snprintf(f, sizeof f, "%s%s", path, suffix[i]);
      /* within one page of the limit: the next page write was refused */
      if (stat(f, &sb) == 0 && (uint64_t)sb.st_size + 65536u >= (uint64_t)rl.rlim_cur) return true;
    }
  }
  return false;
}

/* SQLITE_FULL is a write that came up short. A write refused outright
 * (EFBIG past a file-size limit, EDQUOT) arrives as SQLITE_IOERR_WRITE, and
 * SQLite does not reliably keep the errno (sqlite3_system_errno reads it
 * after later calls), so the file system and the limit are asked. */
static bool is_disk_full(store_t *s, int rc) {
  if ((rc & 0xff) == SQLITE_FULL) return true;
  int sys = sqlite3_system_errno(s->db);
  if ((rc & 0xff) == SQLITE_IOERR && (sys == ENOSPC || sys == EFBIG || sys == EDQUOT)) return true;
  return (rc & 0xff) == SQLITE_IOERR && no_room(s->path);
}

/* A write failed (rc): stop the store for good. The open batch is rolled
 * back (SQLite may already have done so; either way the file keeps every
 * committed batch and stays consistent), the counts go back to what is
 * committed, and every later write fails with the same message, so a
 * caller that keeps going cannot half-write anything. */
static int write_failed(store_t *s, verr_t *err, const char *what, int rc) {
  if (!s->failed) {
    s->disk_full = is_disk_full(s, rc);
    if (s->disk_full)
      snprintf(s->fail_msg, sizeof s->fail_msg, "%s: disk full (%s: %s); recording stopped", s->path, what,
               sqlite3_errmsg(s->db));
    else
      snprintf(s->fail_msg, sizeof s->fail_msg, "%s: %s: %s; recording stopped", s->path, what, sqlite3_errmsg(s->db));
    if (!sqlite3_get_autocommit(s->db)) sqlite3_exec(s->db, "ROLLBACK;", NULL, NULL, NULL);
    s->in_txn = false;
    s->total_samples = s->committed_samples;
    s->total_bytes = s->committed_bytes;
    s->failed = true;
  }
  return verr_set(err, "%s", s->fail_msg);
}

static int exec_sql(store_t *s, const char *sql, verr_t *err) {
  char *msg = NULL;
  if (sqlite3_exec(s->db, sql, NULL, NULL, &msg) != SQLITE_OK) {
    verr_set(err, "%s: %s (while running: %.60s)", s->path, msg ? msg : "unknown SQLite error", sql);
    sqlite3_free(msg);
    return -1;
  }
  return 0;
}

static int prepare(store_t *s, const char *sql, sqlite3_stmt **st, verr_t *err) {
  if (sqlite3_prepare_v3(s->db, sql, -1, SQLITE_PREPARE_PERSISTENT, st, NULL) != SQLITE_OK)
    return db_fail(s, err, "cannot prepare statement");
  return 0;
}

/* A new recording must not silently replace another one, and a stale WAL
 * left by a killed recorder next to a fresh file could be replayed into it
 * by SQLite's recovery, so a non-empty "-wal" counts as "exists" too.
 * Side files that hold nothing (left by readers of an old file of the same
 * name) are removed. */
static int claim_path(const char *path, bool force, verr_t *err) {
  char wal[4096];
  const char *suffixes[] = {"-wal", "-shm", "-journal"};
  if ((size_t)snprintf(wal, sizeof wal, "%s-wal", path) >= sizeof wal) return verr_set(err, "%s: path too long", path);
  if (!force) {
    struct stat sb;
    if (stat(path, &sb) == 0) return verr_set(err, "%s: file exists (use --force to overwrite)", path);
    if (stat(wal, &sb) == 0 && sb.st_size > 0)
      return verr_set(err, "%s: a stale %s exists (use --force to overwrite)", path, wal);
  } else if (unlink(path) != 0 && errno != ENOENT) {
    return verr_set(err, "%s: cannot remove existing file: %s", path, strerror(errno));
  }
  for (size_t i = 0; i < sizeof suffixes / sizeof suffixes[0]; i++) {
    char side[4096];
    snprintf(side, sizeof side, "%s%s", path, suffixes[i]);
    if (unlink(side) != 0 && errno != ENOENT)
      return verr_set(err, "%s: cannot remove stale %s: %s", path, side, strerror(errno));
  }
  /* O_EXCL: two recorders started on the same name cannot both win. */
  int fd = open(path, O_WRONLY | O_CREAT | O_EXCL, 0644);
  if (fd < 0) {
    if (errno == EEXIST) return verr_set(err, "%s: file exists (use --force to overwrite)", path);
    return verr_set(err, "%s: cannot create: %s", path, strerror(errno));
  }
  close(fd);
  return 0;
}

int store_open(store_t **out, const char *path, bool force, const store_session_t *meta, verr_t *err) {
  *out = NULL;
  if (claim_path(path, force, err) < 0) return -1;
  store_t *s = calloc(1, sizeof *s);
  if (!s || !(s->path = strdup(path))) {
    free(s);
    return verr_set(err, "%s: out of memory", path);
  }
  s->limits = STORE_DEFAULT_LIMITS;
  if (sqlite3_open_v2(path, &s->db, SQLITE_OPEN_READWRITE, NULL) != SQLITE_OK) {
    db_fail(s, err, "cannot open");
    goto fail;
  }
  /* page_size before the first table; WAL so readers (recinfo on a live
   * recording) never block the recorder and a crash never corrupts;
   * synchronous=NORMAL: in WAL mode a commit is then durable against a
   * process crash without an fsync per batch. */
  char pragmas[256];
  snprintf(pragmas, sizeof pragmas,
           "PRAGMA page_size=8192; PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL;"
           " PRAGMA application_id=%d; PRAGMA user_version=%d;",
           REC_APPLICATION_ID, REC_FORMAT_VERSION);
  if (exec_sql(s, pragmas, err) < 0) goto fail;
  if (exec_sql(s, "BEGIN;", err) < 0) goto fail;
  if (exec_sql(s, REC_SCHEMA_SQL, err) < 0) goto fail;
  sqlite3_stmt *st = NULL;
  if (prepare(s,
              "INSERT INTO session (format_version, scene, partition, domain, start_wall_ns, hostname,"
              " recorder_version, dds_version) VALUES (?,?,?,?,?,?,?,?)",
              &st, err) < 0)
    goto fail;
  sqlite3_bind_int(st, 1, REC_FORMAT_VERSION);
  sqlite3_bind_text(st, 2, meta->scene, -1, SQLITE_TRANSIENT);
  sqlite3_bind_text(st, 3, meta->partition ? meta->partition : "", -1, SQLITE_TRANSIENT);
  sqlite3_bind_int(st, 4, meta->domain);
  sqlite3_bind_int64(st, 5, meta->start_wall_ns);
  sqlite3_bind_text(st, 6, meta->hostname, -1, SQLITE_TRANSIENT);
  sqlite3_bind_text(st, 7, meta->recorder_version, -1, SQLITE_TRANSIENT);
  sqlite3_bind_text(st, 8, DDS_PROJECT_NAME " " DDS_VERSION, -1, SQLITE_STATIC);
  int rc = sqlite3_step(st);
  sqlite3_finalize(st);
  if (rc != SQLITE_DONE) {
    db_fail(s, err, "cannot write session row");
    goto fail;
  }
  if (exec_sql(s, "COMMIT;", err) < 0) goto fail;
  if (prepare(s,
              "INSERT INTO samples (topic_id, writer_id, source_ts_ns, recv_wall_ns, kind, inferred, cdr)"
              " VALUES (?,?,?,?,?,?,?)",
              &s->ins_sample, err) < 0 ||
      prepare(s,
              "INSERT INTO topics (name, type_name, desc_size, desc_align, desc_flagset, nkeys, nops, ops,"
              " typeinfo, typemap, restrict_data_representation, reliability, max_blocking_ns, durability,"
              " history, history_depth, durability_service_history, durability_service_depth, deadline_ns,"
              " liveliness, liveliness_lease_ns, ownership, ownership_strength, data_representation,"
              " discovered_wall_ns) VALUES (?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)",
              &s->ins_topic, err) < 0 ||
      prepare(s, "INSERT INTO topic_keys (topic_id, idx, name, offset, key_index) VALUES (?,?,?,?,?)", &s->ins_key,
              err) < 0 ||
      prepare(s, "INSERT INTO writers (topic_id, guid, partitions, first_seen_wall_ns) VALUES (?,?,?,?)",
              &s->ins_writer, err) < 0 ||
      prepare(s,
              "INSERT INTO participants (guid, user_data, role, first_seen_wall_ns, last_seen_wall_ns)"
              " VALUES (?1,?2,?3,?4,?4) ON CONFLICT(guid) DO UPDATE SET user_data=excluded.user_data,"
              " role=excluded.role, last_seen_wall_ns=excluded.last_seen_wall_ns, left_wall_ns=NULL",
              &s->ins_part, err) < 0 ||
      prepare(s, "UPDATE participants SET last_seen_wall_ns=?1, left_wall_ns=?1 WHERE guid=?2 AND left_wall_ns IS NULL",
              &s->left_part, err) < 0 ||
      prepare(s, "UPDATE participants SET subject=?1 WHERE guid=?2", &s->subj_part, err) < 0)
    goto fail;
  *out = s;
  return 0;
fail:
  sqlite3_finalize(s->ins_sample);
  sqlite3_finalize(s->ins_topic);
  sqlite3_finalize(s->ins_key);
  sqlite3_finalize(s->ins_writer);
  sqlite3_finalize(s->ins_part);
  sqlite3_finalize(s->left_part);
  sqlite3_finalize(s->subj_part);
  sqlite3_close(s->db);
  free(s->path);
  free(s);
  return -1;
}

void store_set_limits(store_t *s, store_batch_limits_t limits) { s->limits = limits; }

static int begin_if_needed(store_t *s, verr_t *err) {
  if (s->failed) return verr_set(err, "%s", s->fail_msg);
  if (s->in_txn) return 0;
  int rc = sqlite3_exec(s->db, "BEGIN;", NULL, NULL, NULL);
  if (rc != SQLITE_OK) return write_failed(s, err, "cannot begin a batch", rc);
  s->in_txn = true;
  s->batch_start_ns = vtime_mono_ns();
  s->batch_samples = 0;
  s->batch_bytes = 0;
  return 0;
}

int store_commit(store_t *s, verr_t *err) {
  if (s->failed) return verr_set(err, "%s", s->fail_msg);
  if (!s->in_txn) return 0;
  int rc = sqlite3_exec(s->db, "COMMIT;", NULL, NULL, NULL);
  /* A failed COMMIT (disk full, I/O error) may leave the transaction open:
   * write_failed rolls it back so the file keeps every earlier batch. */
  if (rc != SQLITE_OK) return write_failed(s, err, "cannot commit a batch", rc);
  s->in_txn = false;
  s->committed_samples = s->total_samples;
  s->committed_bytes = s->total_bytes;
  return 0;
}

int store_commit_if_due(store_t *s, uint64_t now_mono_ns, verr_t *err) {
  if (s->in_txn && now_mono_ns - s->batch_start_ns >= s->limits.max_age_ns) return store_commit(s, err);
  return 0;
}

static int step_reset(store_t *s, sqlite3_stmt *st, verr_t *err, const char *what) {
  int rc = sqlite3_step(st);
  sqlite3_reset(st);
  sqlite3_clear_bindings(st);
  return rc == SQLITE_DONE ? 0 : write_failed(s, err, what, rc);
}

static const char *reliability_name(dds_reliability_kind_t k) {
  return k == DDS_RELIABILITY_RELIABLE ? "reliable" : "best_effort";
}

static const char *durability_name(dds_durability_kind_t k) {
  switch (k) {
  case DDS_DURABILITY_VOLATILE:
    return "volatile";
  case DDS_DURABILITY_TRANSIENT_LOCAL:
    return "transient_local";
  case DDS_DURABILITY_TRANSIENT:
    return "transient";
  case DDS_DURABILITY_PERSISTENT:
    return "persistent";
  }
  return "?";
}

static const char *history_name(dds_history_kind_t k) { return k == DDS_HISTORY_KEEP_ALL ? "keep_all" : "keep_last"; }

static const char *liveliness_name(dds_liveliness_kind_t k) {
  switch (k) {
  case DDS_LIVELINESS_AUTOMATIC:
    return "automatic";
  case DDS_LIVELINESS_MANUAL_BY_PARTICIPANT:
    return "manual_by_participant";
  case DDS_LIVELINESS_MANUAL_BY_TOPIC:
    return "manual_by_topic";
  }
  return "?";
}

/* Binds the QoS columns (12..24) of the topic insert. A policy the writer
 * did not send is stored as its DDS default, except the optional columns
 * which stay NULL, so replay can tell "not sent" from "default". */
static void bind_qos(sqlite3_stmt *st, const dds_qos_t *qos) {
  dds_reliability_kind_t rel = DDS_RELIABILITY_BEST_EFFORT;
  dds_duration_t blocking = 0;
  if (qos && dds_qget_reliability(qos, &rel, &blocking)) sqlite3_bind_int64(st, 13, blocking);
  sqlite3_bind_text(st, 12, reliability_name(rel), -1, SQLITE_STATIC);
  dds_durability_kind_t dur = DDS_DURABILITY_VOLATILE;
  if (qos) dds_qget_durability(qos, &dur);
  sqlite3_bind_text(st, 14, durability_name(dur), -1, SQLITE_STATIC);
  dds_history_kind_t hk = DDS_HISTORY_KEEP_LAST;
  int32_t depth = 1;
  bool have_hist = qos && dds_qget_history(qos, &hk, &depth);
  sqlite3_bind_text(st, 15, history_name(hk), -1, SQLITE_STATIC);
  if (have_hist) sqlite3_bind_int(st, 16, depth);
  dds_duration_t ds_delay;
  dds_history_kind_t ds_hk;
  int32_t ds_depth, ds_s, ds_i, ds_spi;
  if (qos && dds_qget_durability_service(qos, &ds_delay, &ds_hk, &ds_depth, &ds_s, &ds_i, &ds_spi)) {
    sqlite3_bind_text(st, 17, history_name(ds_hk), -1, SQLITE_STATIC);
    sqlite3_bind_int(st, 18, ds_depth);
  }
  dds_duration_t deadline;
  if (qos && dds_qget_deadline(qos, &deadline)) sqlite3_bind_int64(st, 19, deadline);
  dds_liveliness_kind_t lk;
  dds_duration_t lease;
  if (qos && dds_qget_liveliness(qos, &lk, &lease)) {
    sqlite3_bind_text(st, 20, liveliness_name(lk), -1, SQLITE_STATIC);
    sqlite3_bind_int64(st, 21, lease);
  }
  dds_ownership_kind_t own;
  if (qos && dds_qget_ownership(qos, &own))
    sqlite3_bind_text(st, 22, own == DDS_OWNERSHIP_EXCLUSIVE ? "exclusive" : "shared", -1, SQLITE_STATIC);
  int32_t strength;
  if (qos && dds_qget_ownership_strength(qos, &strength)) sqlite3_bind_int(st, 23, strength);
  uint32_t nrep = 0;
  dds_data_representation_id_t *reps = NULL;
  if (qos && dds_qget_data_representation(qos, &nrep, &reps) && nrep > 0) {
    char buf[64] = "";
    size_t len = 0;
    for (uint32_t i = 0; i < nrep && len + 8 < sizeof buf; i++) {
      const char *n = reps[i] == DDS_DATA_REPRESENTATION_XCDR1   ? "xcdr1"
                      : reps[i] == DDS_DATA_REPRESENTATION_XCDR2 ? "xcdr2"
                                                                 : "xml";
      len += (size_t)snprintf(buf + len, sizeof buf - len, "%s%s", i ? "," : "", n);
    }
    sqlite3_bind_text(st, 24, buf, -1, SQLITE_TRANSIENT);
  }
  dds_free(reps);
}

int store_add_topic(store_t *s, const char *name, const dds_topic_descriptor_t *desc, const dds_qos_t *qos,
                    int64_t wall_ns, int64_t *id, verr_t *err) {
  if (begin_if_needed(s, err) < 0) return -1;
  /* m_nops counts instructions, not words; the ops array's real length
   * comes from dds_stream_countops (a wrong length makes a rebuilt
   * descriptor hang dds_create_topic, see docs/dds.md, "Topic descriptors"). */
  uint32_t nops = dds_stream_countops(desc->m_ops, desc->m_nkeys, desc->m_keys);
  unsigned char *ops = malloc((size_t)nops * 4u + 1u);
  if (!ops) return verr_set(err, "%s: out of memory", s->path);
  for (uint32_t i = 0; i < nops; i++) {
    uint32_t w = desc->m_ops[i];
    ops[4 * i + 0] = (unsigned char)(w & 0xff);
    ops[4 * i + 1] = (unsigned char)((w >> 8) & 0xff);
    ops[4 * i + 2] = (unsigned char)((w >> 16) & 0xff);
    ops[4 * i + 3] = (unsigned char)((w >> 24) & 0xff);
  }
  sqlite3_stmt *st = s->ins_topic;
  sqlite3_bind_text(st, 1, name, -1, SQLITE_STATIC);
  sqlite3_bind_text(st, 2, desc->m_typename, -1, SQLITE_STATIC);
  sqlite3_bind_int64(st, 3, desc->m_size);
  sqlite3_bind_int64(st, 4, desc->m_align);
  sqlite3_bind_int64(st, 5, desc->m_flagset);
  sqlite3_bind_int64(st, 6, desc->m_nkeys);
  sqlite3_bind_int64(st, 7, nops);
  sqlite3_bind_blob(st, 8, ops, (int)(nops * 4u), SQLITE_STATIC);
  if (desc->type_information.data && desc->type_information.sz)
    sqlite3_bind_blob(st, 9, desc->type_information.data, (int)desc->type_information.sz, SQLITE_STATIC);
  if (desc->type_mapping.data && desc->type_mapping.sz)
    sqlite3_bind_blob(st, 10, desc->type_mapping.data, (int)desc->type_mapping.sz, SQLITE_STATIC);
  sqlite3_bind_int64(st, 11, desc->restrict_data_representation);
  bind_qos(st, qos);
  sqlite3_bind_int64(st, 25, wall_ns);
  int rc = step_reset(s, st, err, "cannot add topic");
  free(ops);
  if (rc < 0) return -1;
  *id = sqlite3_last_insert_rowid(s->db);
  for (uint32_t k = 0; k < desc->m_nkeys; k++) {
    sqlite3_bind_int64(s->ins_key, 1, *id);
    sqlite3_bind_int64(s->ins_key, 2, k);
    sqlite3_bind_text(s->ins_key, 3, desc->m_keys[k].m_name, -1, SQLITE_STATIC);
    sqlite3_bind_int64(s->ins_key, 4, desc->m_keys[k].m_offset);
    sqlite3_bind_int64(s->ins_key, 5, desc->m_keys[k].m_idx);
    if (step_reset(s, s->ins_key, err, "cannot add topic key") < 0) return -1;
  }
  return 0;
}

void store_guid_hex(const uint8_t guid[16], char out[33]) {
  static const char hex[] = "0123456789abcdef";
  for (int i = 0; i < 16; i++) {
    out[2 * i] = hex[guid[i] >> 4];
    out[2 * i + 1] = hex[guid[i] & 15];
  }
  out[32] = 0;
}

int store_add_writer(store_t *s, int64_t topic_id, const uint8_t guid[16], const char *partitions, int64_t wall_ns,
                     int64_t *id, verr_t *err) {
  if (begin_if_needed(s, err) < 0) return -1;
  char hex[33];
  store_guid_hex(guid, hex);
  sqlite3_stmt *st = s->ins_writer;
  sqlite3_bind_int64(st, 1, topic_id);
  sqlite3_bind_text(st, 2, hex, -1, SQLITE_STATIC);
  sqlite3_bind_text(st, 3, partitions, -1, SQLITE_STATIC);
  sqlite3_bind_int64(st, 4, wall_ns);
  if (step_reset(s, st, err, "cannot add writer") < 0) return -1;
  *id = sqlite3_last_insert_rowid(s->db);
  return 0;
}

int store_add_sample(store_t *s, const store_sample_t *smp, verr_t *err) {
  if (smp->cdr_len > (size_t)INT32_MAX)
    return verr_set(err, "%s: sample of %zu bytes too large", s->path, smp->cdr_len);
  if (begin_if_needed(s, err) < 0) return -1;
  sqlite3_stmt *st = s->ins_sample;
  sqlite3_bind_int64(st, 1, smp->topic_id);
  if (smp->writer_id > 0) sqlite3_bind_int64(st, 2, smp->writer_id);
  sqlite3_bind_int64(st, 3, smp->source_ts_ns);
  sqlite3_bind_int64(st, 4, smp->recv_wall_ns);
  sqlite3_bind_int(st, 5, smp->kind);
  sqlite3_bind_int(st, 6, smp->inferred ? 1 : 0);
  /* a NULL pointer would bind SQL NULL; an empty payload is still a blob */
  if (smp->cdr_len == 0 || !smp->cdr)
    sqlite3_bind_zeroblob(st, 7, 0);
  else
    sqlite3_bind_blob(st, 7, smp->cdr, (int)smp->cdr_len, SQLITE_STATIC);
  if (step_reset(s, st, err, "cannot store sample") < 0) return -1;
  s->batch_samples++;
  s->batch_bytes += smp->cdr_len;
  s->total_samples++;
  s->total_bytes += smp->cdr_len;
  if (s->batch_samples >= s->limits.max_samples || s->batch_bytes >= s->limits.max_bytes) return store_commit(s, err);
  return 0;
}

void store_counts(const store_t *s, uint64_t *samples, uint64_t *bytes) {
  if (samples) *samples = s->total_samples;
  if (bytes) *bytes = s->total_bytes;
}

bool store_failed(const store_t *s) { return s->failed; }
bool store_disk_full(const store_t *s) { return s->disk_full; }

int store_note_participant(store_t *s, const uint8_t guid[16], const char *user_data, const char *role, bool left,
                           int64_t wall_ns, verr_t *err) {
  if (begin_if_needed(s, err) < 0) return -1;
  char hex[33];
  store_guid_hex(guid, hex);
  sqlite3_stmt *st = left ? s->left_part : s->ins_part;
  if (left) {
    sqlite3_bind_int64(st, 1, wall_ns);
    sqlite3_bind_text(st, 2, hex, -1, SQLITE_STATIC);
  } else {
    sqlite3_bind_text(st, 1, hex, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 2, user_data, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 3, role, -1, SQLITE_STATIC);
    sqlite3_bind_int64(st, 4, wall_ns);
  }
  return step_reset(s, st, err, "cannot note participant");
}

int store_note_subject(store_t *s, const uint8_t guid[16], const char *subject, verr_t *err) {
  if (begin_if_needed(s, err) < 0) return -1;
  char hex[33];
  store_guid_hex(guid, hex);
  sqlite3_bind_text(s->subj_part, 1, subject, -1, SQLITE_STATIC);
  sqlite3_bind_text(s->subj_part, 2, hex, -1, SQLITE_STATIC);
  return step_reset(s, s->subj_part, err, "cannot note participant subject");
}

int store_close(store_t *s, int64_t end_wall_ns, verr_t *err) {
  int ret = store_commit(s, err);
  if (s->failed) {
    /* Stopped by a failed write (disk full): leave the file as readable as
     * possible, best effort. The end time stays NULL (the session went on
     * without us: readers must not take this for a complete recording).
     * A checkpoint moves the WAL's committed batches into the main file
     * (where a file-size limit still has room: its pages are smaller than
     * the WAL's frames) and dropping the WAL leaves one self-contained
     * file; on a truly full disk either may fail, and then the WAL stays
     * next to the file, consistent, and readers use it. */
    sqlite3_exec(s->db, "PRAGMA wal_checkpoint(TRUNCATE);", NULL, NULL, NULL);
    sqlite3_exec(s->db, "PRAGMA journal_mode=DELETE;", NULL, NULL, NULL);
  } else if (ret == 0 && end_wall_ns >= 0) {
    char sql[128];
    snprintf(sql, sizeof sql, "UPDATE session SET end_wall_ns=%lld;", (long long)end_wall_ns);
    ret = exec_sql(s, sql, err);
    /* Participants still present were seen until the end. */
    snprintf(sql, sizeof sql, "UPDATE participants SET last_seen_wall_ns=%lld WHERE left_wall_ns IS NULL;",
             (long long)end_wall_ns);
    if (ret == 0) ret = exec_sql(s, sql, err);
    if (ret == 0) ret = exec_sql(s, REC_INDEX_SQL, err);
    /* A finished recording goes back to a rollback journal: WAL was for
     * crash safety while recording; in WAL mode every later reader, even
     * a read-only one, would leave -wal/-shm files next to it and a copy
     * of the .db alone could miss data. This checkpoints and drops the WAL. */
    if (ret == 0) ret = exec_sql(s, "PRAGMA journal_mode=DELETE;", err);
  }
  sqlite3_finalize(s->ins_sample);
  sqlite3_finalize(s->ins_topic);
  sqlite3_finalize(s->ins_key);
  sqlite3_finalize(s->ins_writer);
  sqlite3_finalize(s->ins_part);
  sqlite3_finalize(s->left_part);
  sqlite3_finalize(s->subj_part);
  /* After a failure the last connection's close still checkpoints the
   * WAL into the main file and removes it. */
  if (sqlite3_close(s->db) != SQLITE_OK && ret == 0) ret = verr_set(err, "%s: close failed", s->path);
  free(s->path);
  free(s);
  return ret;
}
