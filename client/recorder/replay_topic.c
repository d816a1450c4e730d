/* SPDX-License-Identifier: Apache-2.0 */
#include "replay_topic.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <dds/ddsi/ddsi_cdrstream.h>

#include "replay_typecheck.h"

static dds_duration_t col_dur(sqlite3_stmt *st, int col, dds_duration_t dflt) {
  return sqlite3_column_type(st, col) == SQLITE_NULL ? dflt : sqlite3_column_int64(st, col);
}

static const char *col_text(sqlite3_stmt *st, int col) {
  const unsigned char *t = sqlite3_column_text(st, col);
  return t ? (const char *)t : "";
}

static unsigned char *col_blob_dup(sqlite3_stmt *st, int col, uint32_t *len) {
  const void *b = sqlite3_column_blob(st, col);
  int n = sqlite3_column_bytes(st, col);
  *len = 0;
  if (!b || n <= 0) return NULL;
  unsigned char *p = malloc((size_t)n);
  if (!p) return NULL;
  memcpy(p, b, (size_t)n);
  *len = (uint32_t)n;
  return p;
}

/* Speeds below 1 stretch the stream in time: stretch deadline and lease
 * with it so a slow replay does not read as a failing writer. */
static dds_duration_t scaled(const rp_setup_t *r, dds_duration_t d) {
  if (d == DDS_INFINITY || r->speed >= 1.0) return d;
  double v = (double)d / r->speed;
  return v > 9e18 ? DDS_INFINITY : (dds_duration_t)v;
}

/* Durations of the recorded QoS (untrusted; fuzz_recording found a deadline
 * of 0 that made the writer spin and one of 292 years that hung its
 * deletion): NULL or DDS_INFINITY ("not set") is fine, else 1 ms .. 1 day
 * (max_blocking may be 0). Returns NULL or what is wrong. */
static const char *qos_values_ok(sqlite3_stmt *st, char *why, size_t n) {
  static const struct {
    int col;
    const char *name;
  } durs[] = {{13, "max_blocking"}, {19, "deadline"}, {21, "liveliness lease"}};
  for (size_t i = 0; i < sizeof durs / sizeof durs[0]; i++) {
    if (sqlite3_column_type(st, durs[i].col) == SQLITE_NULL) continue;
    int64_t d = sqlite3_column_int64(st, durs[i].col);
    if (d == DDS_INFINITY) continue;
    /* A finite duration near INT64_MAX overflows Cyclone's timers (a
     * deadline of 292 years hung the writer's deletion). */
    if ((d < DDS_MSECS(1) && !(durs[i].col == 13 && d >= 0)) || d > DDS_SECS(86400)) {
      snprintf(why, n, "recorded %s %lld ns out of range (1 ms .. 1 day, or infinite)", durs[i].name, (long long)d);
      return why;
    }
  }
  for (int col = 16; col <= 18; col += 2)
    if (sqlite3_column_type(st, col) != SQLITE_NULL &&
        (sqlite3_column_int64(st, col) < 0 || sqlite3_column_int64(st, col) > 100000)) {
      snprintf(why, n, "recorded history depth %lld out of range (0..100000)",
               (long long)sqlite3_column_int64(st, col));
      return why;
    }
  if (sqlite3_column_type(st, 23) != SQLITE_NULL &&
      (sqlite3_column_int64(st, 23) < INT32_MIN || sqlite3_column_int64(st, 23) > INT32_MAX)) {
    snprintf(why, n, "recorded ownership strength out of range");
    return why;
  }
  return NULL;
}

static dds_qos_t *qos_from_row(const rp_setup_t *r, sqlite3_stmt *st, bool *tl) {
  /* columns: 12 reliability, 13 max_blocking_ns, 14 durability, 15 history, 16 history_depth,
   * 17 ds_history, 18 ds_depth, 19 deadline, 20 liveliness, 21 lease, 22 ownership,
   * 23 strength, 24 data_representation */
  dds_qos_t *q = dds_create_qos();
  if (!q) return NULL;
  bool rel = strcmp(col_text(st, 12), "reliable") == 0;
  dds_qset_reliability(q, rel ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT,
                       col_dur(st, 13, DDS_MSECS(100)));
  const char *dur = col_text(st, 14);
  /* Transient/persistent need a durability service Cyclone does not run:
   * transient-local is what the receivers can actually get. */
  *tl = strcmp(dur, "volatile") != 0;
  dds_qset_durability(q, *tl ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  int depth = sqlite3_column_type(st, 16) == SQLITE_NULL ? 1 : sqlite3_column_int(st, 16);
  if (strcmp(col_text(st, 15), "keep_all") == 0)
    dds_qset_history(q, DDS_HISTORY_KEEP_ALL, DDS_LENGTH_UNLIMITED);
  else
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth > 0 ? depth : 1);
  if (sqlite3_column_type(st, 17) != SQLITE_NULL) {
    int dsd = sqlite3_column_int(st, 18);
    bool all = strcmp(col_text(st, 17), "keep_all") == 0;
    dds_qset_durability_service(q, 0, all ? DDS_HISTORY_KEEP_ALL : DDS_HISTORY_KEEP_LAST, dsd > 0 ? dsd : 1,
                                DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
  }
  if (sqlite3_column_type(st, 19) != SQLITE_NULL) dds_qset_deadline(q, scaled(r, sqlite3_column_int64(st, 19)));
  if (sqlite3_column_type(st, 20) != SQLITE_NULL) {
    const char *lk = col_text(st, 20);
    dds_liveliness_kind_t k = strcmp(lk, "manual_by_topic") == 0         ? DDS_LIVELINESS_MANUAL_BY_TOPIC
                              : strcmp(lk, "manual_by_participant") == 0 ? DDS_LIVELINESS_MANUAL_BY_PARTICIPANT
                                                                         : DDS_LIVELINESS_AUTOMATIC;
    dds_qset_liveliness(q, k, scaled(r, col_dur(st, 21, DDS_INFINITY)));
  }
  if (sqlite3_column_type(st, 22) != SQLITE_NULL)
    dds_qset_ownership(q, strcmp(col_text(st, 22), "exclusive") == 0 ? DDS_OWNERSHIP_EXCLUSIVE : DDS_OWNERSHIP_SHARED);
  /* Ending the replay must not invent disposes the recording does not hold. */
  dds_qset_writer_data_lifecycle(q, false);
  if (sqlite3_column_type(st, 23) != SQLITE_NULL) dds_qset_ownership_strength(q, sqlite3_column_int(st, 23));
  const char *reps = col_text(st, 24);
  if (*reps) {
    dds_data_representation_id_t ids[4];
    uint32_t n = 0;
    char tmp[64];
    snprintf(tmp, sizeof tmp, "%s", reps);
    for (char *save = NULL, *tok = strtok_r(tmp, ",", &save); tok && n < 4; tok = strtok_r(NULL, ",", &save)) {
      if (strcmp(tok, "xcdr1") == 0)
        ids[n++] = DDS_DATA_REPRESENTATION_XCDR1;
      else if (strcmp(tok, "xcdr2") == 0)
        ids[n++] = DDS_DATA_REPRESENTATION_XCDR2;
    }
    if (n) dds_qset_data_representation(q, n, ids);
  }
  return q;
}

void rp_topic_free(rp_topic_t *t) {
  free(t->desc);
  for (uint32_t k = 0; t->keys && k < t->nkeys; k++) free((char *)t->keys[k].m_name);
  free(t->keys);
  free(t->ops);
  free(t->typeinfo);
  free(t->typemap);
  free(t->st_keys);
}

/* Rebuilds one topic's descriptor from its row (columns 0..11) and creates
 * topic and writer. Returns 0, or -1 with err. */
static int setup_topic(const rp_setup_t *r, sqlite3_stmt *st, rp_topic_t *t, verr_t *err) {
  t->id = sqlite3_column_int64(st, 0);
  snprintf(t->name, sizeof t->name, "%s", col_text(st, 1));
  snprintf(t->type_name, sizeof t->type_name, "%s", col_text(st, 2));
  int64_t size = sqlite3_column_int64(st, 3), align = sqlite3_column_int64(st, 4);
  int64_t flagset = sqlite3_column_int64(st, 5), nkeys = sqlite3_column_int64(st, 6);
  int64_t nops = sqlite3_column_int64(st, 7);
  int opsbytes = sqlite3_column_bytes(st, 8);
  const unsigned char *opsblob = sqlite3_column_blob(st, 8);
  if (size <= 0 || size > (1 << 24) || align <= 0 || align > 64 || flagset < 0 || flagset > UINT32_MAX || nkeys < 0 ||
      nkeys > 64 || nops <= 0 || nops > (1 << 20) || !opsblob || (int64_t)opsbytes != nops * 4)
    return verr_set(err, "topic %s: stored type descriptor is inconsistent (size %lld, %lld ops in %d bytes)", t->name,
                    (long long)size, (long long)nops, opsbytes);
  /* Zero words (DDS_OP_RTS) after the stored ops stop a walk over a
   * garbled program before it leaves the buffer. */
  t->ops = calloc((size_t)nops + 64, sizeof *t->ops);
  if (!t->ops) return verr_set(err, "out of memory");
  for (int64_t i = 0; i < nops; i++) {
    const unsigned char *p = opsblob + 4 * i;
    t->ops[i] = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
  }
  uint32_t tilen = 0, tmlen = 0;
  t->typeinfo = col_blob_dup(st, 9, &tilen);
  t->typemap = col_blob_dup(st, 10, &tmlen);
  uint32_t restrict_rep = (uint32_t)sqlite3_column_int64(st, 11);

  /* keys */
  if (nkeys > 0) {
    t->keys = calloc((size_t)nkeys, sizeof *t->keys);
    t->st_keys = calloc((size_t)nkeys, sizeof *t->st_keys);
    if (!t->keys || !t->st_keys) return verr_set(err, "out of memory");
    sqlite3_stmt *ks = NULL;
    if (sqlite3_prepare_v2(r->db,
                           "SELECT idx, name, offset, key_index FROM topic_keys WHERE topic_id = ?1 ORDER BY idx", -1,
                           &ks, NULL) != SQLITE_OK)
      return verr_set(err, "topic %s: key table unreadable: %s", t->name, sqlite3_errmsg(r->db));
    sqlite3_bind_int64(ks, 1, t->id);
    int64_t n = 0;
    while (sqlite3_step(ks) == SQLITE_ROW && n < nkeys) {
      int64_t off = sqlite3_column_int64(ks, 2), kidx = sqlite3_column_int64(ks, 3);
      if (off < 0 || off >= nops || kidx < 0 || kidx >= nkeys) break;
      t->keys[n].m_name = strdup(col_text(ks, 1));
      t->keys[n].m_offset = (uint32_t)off;
      t->keys[n].m_idx = (uint32_t)kidx;
      t->st_keys[n].ops_offs = (uint32_t)off;
      t->st_keys[n].idx = (uint32_t)kidx;
      n++;
      t->nkeys = (uint32_t)n;
    }
    sqlite3_finalize(ks);
    if (n != nkeys)
      return verr_set(err, "topic %s: %lld key descriptors stored, %lld expected", t->name, (long long)n,
                      (long long)nkeys);
  }
  dds_topic_descriptor_t tmpl = {.m_size = (uint32_t)size,
                                 .m_align = (uint32_t)align,
                                 .m_flagset = (uint32_t)flagset,
                                 .m_nkeys = (uint32_t)nkeys,
                                 .m_typename = t->type_name,
                                 .m_keys = t->keys,
                                 .m_nops = (uint32_t)nops,
                                 .m_ops = t->ops,
                                 .m_meta = "",
                                 .type_information = {t->typeinfo, tilen},
                                 .type_mapping = {t->typemap, tmlen},
                                 .restrict_data_representation = restrict_rep};
  t->desc = malloc(sizeof *t->desc);
  if (!t->desc) return verr_set(err, "out of memory");
  memcpy(t->desc, &tmpl, sizeof tmpl);

  /* The cdrstream view of the same descriptor (checks and decodes stored bytes). */
  memset(&t->st, 0, sizeof t->st);
  t->st.type.size = (uint32_t)size;
  t->st.type.align = (uint32_t)align;
  t->st.type.flagset = (uint32_t)flagset;
  t->st.type.keys.nkeys = (uint32_t)nkeys;
  t->st.type.keys.keys = t->st_keys;
  t->st.type.ops.nops = (uint32_t)nops;
  t->st.type.ops.ops = t->ops;

  /* Cyclone trusts a descriptor: a NULL or damaged type mapping crashes
   * dds_create_topic, a damaged program makes the op counter below loop.
   * Both are checked first (replay_typecheck.h). */
  char why[200];
  if (rp_ops_check(t->ops, (uint32_t)nops, (uint32_t)size, t->nkeys, t->keys, why, sizeof why))
    return verr_set(err, "topic %s: stored type program is damaged: %s", t->name, why);
  const rp_type_verdict_t *v = NULL;
  for (size_t i = 0; r->verdicts && i < r->nverdicts; i++)
    if (r->verdicts[i].id == t->id) v = &r->verdicts[i];
  if (v ? !v->ok : rp_types_check(t->typeinfo, tilen, t->typemap, tmlen, why, sizeof why) != 0)
    return verr_set(err, "topic %s: stored type information is damaged: %s", t->name, v ? v->why : why);
  /* A wrong ops length makes dds_create_topic hang (docs/dds.md, "Topic descriptors"): the stored
   * count must be what Cyclone counts in the stored program. */
  uint32_t counted = dds_stream_countops(t->ops, t->nkeys, t->keys);
  if (counted != (uint32_t)nops)
    return verr_set(err, "topic %s: stored type program is damaged (%u ops counted, %lld stored)", t->name, counted,
                    (long long)nops);
  t->topic = dds_create_topic(r->pp, t->desc, t->name, NULL, NULL);
  if (t->topic < 0)
    return verr_set(err, "topic %s (type %s): cannot create from the stored descriptor: %s", t->name, t->type_name,
                    dds_strretcode(t->topic));
  const char *qbad = qos_values_ok(st, why, sizeof why);
  if (qbad) return verr_set(err, "topic %s: %s", t->name, qbad);
  dds_qos_t *q = qos_from_row(r, st, &t->transient_local);
  if (!q) return verr_set(err, "out of memory");
  t->writer = dds_create_writer(r->pub, t->topic, q, NULL);
  dds_delete_qos(q);
  if (t->writer < 0)
    return verr_set(err, "topic %s: cannot create a writer with the recorded QoS: %s", t->name,
                    dds_strretcode(t->writer));
  return 0;
}

int rp_topics_setup(const rp_setup_t *r, rp_topic_t **topics, size_t *ntopics, verr_t *err) {
  sqlite3_stmt *st = NULL;
  if (sqlite3_prepare_v2(r->db,
                         "SELECT id, name, type_name, desc_size, desc_align, desc_flagset, nkeys, nops, ops, typeinfo,"
                         " typemap, restrict_data_representation, reliability, max_blocking_ns, durability, history,"
                         " history_depth, durability_service_history, durability_service_depth, deadline_ns,"
                         " liveliness, liveliness_lease_ns, ownership, ownership_strength, data_representation"
                         " FROM topics ORDER BY id",
                         -1, &st, NULL) != SQLITE_OK)
    return verr_set(err, "%s: topic table unreadable: %s", r->path, sqlite3_errmsg(r->db));
  int rc;
  while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
    rp_topic_t *n = realloc(*topics, (*ntopics + 1) * sizeof *n);
    if (!n) break;
    *topics = n;
    rp_topic_t *t = &(*topics)[*ntopics];
    memset(t, 0, sizeof *t);
    verr_t e;
    if (setup_topic(r, st, t, &e) < 0) {
      fprintf(stderr, "replay: NOT replayed: %s\n", e.msg);
      if (r->refused) (*r->refused)++;
      if (t->writer > 0) dds_delete(t->writer);
      if (t->topic > 0) dds_delete(t->topic);
      rp_topic_free(t);
      continue;
    }
    (*ntopics)++;
  }
  if (rc != SQLITE_DONE && rc != SQLITE_ROW)
    fprintf(stderr, "replay: %s: topic table partly unreadable: %s\n", r->path, sqlite3_errmsg(r->db));
  sqlite3_finalize(st);
  if (*ntopics == 0) return verr_set(err, "%s: no topic could be set up for replay", r->path);
  return 0;
}

int rp_types_precheck(sqlite3 *db, const char *path, rp_type_verdict_t **out, size_t *n, verr_t *err) {
  *out = NULL;
  *n = 0;
  sqlite3_stmt *st = NULL;
  if (sqlite3_prepare_v2(db, "SELECT id, typeinfo, typemap FROM topics ORDER BY id", -1, &st, NULL) != SQLITE_OK)
    return verr_set(err, "%s: topic table unreadable: %s", path, sqlite3_errmsg(db));
  while (sqlite3_step(st) == SQLITE_ROW) {
    rp_type_verdict_t *grown = realloc(*out, (*n + 1) * sizeof *grown);
    if (!grown) break;
    *out = grown;
    rp_type_verdict_t *v = &grown[(*n)++];
    memset(v, 0, sizeof *v);
    v->id = sqlite3_column_int64(st, 0);
    const unsigned char *ti = sqlite3_column_blob(st, 1);
    uint32_t tilen = (uint32_t)sqlite3_column_bytes(st, 1);
    const unsigned char *tm = sqlite3_column_blob(st, 2);
    uint32_t tmlen = (uint32_t)sqlite3_column_bytes(st, 2);
    v->ok = rp_types_check(ti, tilen, tm, tmlen, v->why, sizeof v->why) == 0;
  }
  sqlite3_finalize(st);
  return 0;
}
