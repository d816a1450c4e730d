/* viscera-replay: republishes a session recording (recording.h) over DDS,
 * with no compiled-in type.
 *
 * For every recorded topic the type descriptor is rebuilt from the stored
 * fields (size, align, flagset, keys, ops, type information and mapping),
 * the topic created with it and a writer with the recorded QoS. Samples are
 * then published in recorded (insertion) order at their original pace
 * (source timestamps, scaled by --speed).
 *
 * How a sample is written: the stored CDR is first checked with
 * dds_stream_normalize against the rebuilt type program (on a copy; a
 * sample that fails is counted and skipped, never handed to DDS). Data
 * rows and explicit dispose/unregister rows (key-only CDR) are then wrapped,
 * bytes unchanged, in a small custom serdata (replay_serdata.c) carrying the
 * ORIGINAL source timestamp and status info, and sent with dds_forwardcdr:
 * Cyclone converts it to the writer's type (which computes key and
 * instance) and keeps timestamp and status. Dispose/unregister rows the
 * recorder inferred from instance state hold a full sample; those are
 * decoded (dds_stream_read_sample) and sent with dds_dispose_ts /
 * dds_unregister_instance_ts, again with the original timestamp.
 *
 * Pause: SIGUSR1 toggles pause/resume, --pause-at S pauses once when the
 * replay reaches recording time S. While paused nothing is written; at
 * resume the rest of the schedule is shifted by the paused time
 * (replay_pause.h), so the samples keep their original spacing.
 *
 * usage: viscera-replay FILE.db [--domain N] [--partition P] [--speed X]
 *                       [--seek S] [--pause-at S] [--loop] [--quiet] */
#include <errno.h>
#include <getopt.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <dds/dds.h>
#include <dds/ddsi/ddsi_cdrstream.h>
#include <dds/ddsi/ddsi_serdata_default.h>
#include <sqlite3.h>

#include "recording/recfile.h"
#include "recording/recording.h"
#include "replay_pause.h"
#include "replay_serdata.h"
#include "dds/vdds_ident.h"
#include "cli.h"
#include "verr.h"
#include "vsignal.h"
#include "dds/vdds_ident.h"

typedef struct rp_topic {
  int64_t id;
  char name[256];
  char type_name[256];
  dds_topic_descriptor_t *desc;
  dds_key_descriptor_t *keys;
  uint32_t *ops;
  unsigned char *typeinfo, *typemap;
  struct ddsi_sertype_default st; /* only the descriptor part is used: for the cdrstream calls */
  ddsi_sertype_default_desc_key_t *st_keys;
  uint32_t nkeys; /* entries of keys filled (names owned) */
  dds_entity_t topic, writer;
  bool transient_local;
  uint64_t written, bad;
} rp_topic_t;

typedef struct replay {
  const char *path;
  int domain;
  char partition[256];
  double speed, seek;
  double pause_at; /* recording time to pause at once, s; < 0: none */
  bool pause_at_done;
  rpause_t pause;
  bool loop, quiet;
  recfile_t *rf;
  sqlite3 *db;
  rp_topic_t *topics;
  size_t ntopics;
  dds_entity_t pp, pub;
  int64_t t0, t_end;
  /* per pass */
  int64_t start_mono, sched_ts, last_progress;
  uint64_t pass_rows;
  uint64_t total_written, total_bad, total_skipped;
  unsigned char *buf;
  size_t bufcap;
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

static void usage(FILE *f) {
  fprintf(f, "usage: viscera-replay FILE.db [--domain N] [--partition P] [--speed X] [--seek S] [--pause-at S]\n"
             "                      [--loop] [--quiet]\n"
             "  --domain N      DDS domain to publish in (default: the recorded one)\n"
             "  --partition P   partition to publish in (default: the recorded one, if not a pattern)\n"
             "  --speed X       playback speed factor, > 0 (default 1)\n"
             "  --seek S        skip the first S seconds (transient-local state is still sent)\n"
             "  --pause-at S    pause when the replay reaches recording time S seconds (once)\n"
             "  --loop          start over at the end until interrupted\n"
             "  --quiet         no progress lines\n"
             "  --help          this text\n"
             "  --version       print the version and exit\n"
             "SIGUSR1 toggles pause/resume; after a resume the original timing goes on\n"
             "(the schedule is shifted by the paused time, no burst of missed samples).\n");
}

enum { OPT_SPEED = 's', OPT_SEEK = 'k', OPT_LOOP = 'l', OPT_PAUSE_AT = 'P' };

/* A number in lo..hi (lo itself allowed only when `lo_ok`), or -1 after the
 * message "replay: --NAME 'ARG': expected WHAT". */
static int number(const char *name, const char *arg, double lo, int lo_ok, double hi, const char *what, double *out) {
  char *end;
  *out = strtod(arg, &end);
  if (*end || end == arg || !(*out > lo || (lo_ok && *out == lo)) || *out > hi) {
    fprintf(stderr, "replay: --%s '%s': expected %s\n", name, arg, what);
    return 1;
  }
  return 0;
}

static int on_option(void *ctx, int code, const char *arg) {
  replay_t *r = ctx;
  switch (code) {
  case OPT_SPEED:
    return number("speed", arg, 0.0, 0, 1e6, "a number > 0", &r->speed);
  case OPT_PAUSE_AT:
    return number("pause-at", arg, 0.0, 1, 1e8, "seconds >= 0", &r->pause_at);
  case OPT_SEEK:
    return number("seek", arg, 0.0, 1, 1e8, "seconds >= 0", &r->seek);
  case OPT_LOOP:
    r->loop = true;
    return 0;
  }
  return 0; /* not reached: cli_parse passes only the codes above */
}

/* Returns CLI_RUN, or the exit code (0 after --help/--version, 1 on a
 * usage error, as replay always had). */
static int parse_args(replay_t *r, int argc, char **argv) {
  static const struct option opts[] = {{"speed", required_argument, NULL, OPT_SPEED},
                                       {"seek", required_argument, NULL, OPT_SEEK},
                                       {"loop", no_argument, NULL, OPT_LOOP},
                                       {"pause-at", required_argument, NULL, OPT_PAUSE_AT},
                                       {NULL, 0, NULL, 0}};
  const cli_spec_t spec = {.program = "viscera-replay",
                           .tag = "replay",
                           .common = CLI_DOMAIN | CLI_PARTITION | CLI_QUIET,
                           .options = opts,
                           .option = on_option,
                           .usage = usage,
                           .domain_error = "--domain '%s': expected an integer 0..230",
                           .partition_error = "--partition: empty or too long",
                           .partition_max = sizeof r->partition,
                           .usage_status = 1};
  r->speed = 1.0;
  r->pause_at = -1.0;
  cli_common_t common = {.domain = -1}; /* -1: the recorded one */
  int rc = cli_parse(&spec, argc, argv, &common, r);
  if (rc != CLI_RUN) return rc;
  r->domain = common.domain;
  if (common.partition) snprintf(r->partition, sizeof r->partition, "%s", common.partition);
  r->quiet = common.quiet;
  if (optind != argc - 1) {
    usage(stderr);
    return 1;
  }
  r->path = argv[optind];
  return CLI_RUN;
}

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
static dds_duration_t scaled(const replay_t *r, dds_duration_t d) {
  if (d == DDS_INFINITY || r->speed >= 1.0) return d;
  double v = (double)d / r->speed;
  return v > 9e18 ? DDS_INFINITY : (dds_duration_t)v;
}

static dds_qos_t *qos_from_row(const replay_t *r, sqlite3_stmt *st, bool *tl) {
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

static void topic_free(rp_topic_t *t) {
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
static int setup_topic(replay_t *r, sqlite3_stmt *st, rp_topic_t *t, verr_t *err) {
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
  dds_qos_t *q = qos_from_row(r, st, &t->transient_local);
  if (!q) return verr_set(err, "out of memory");
  t->writer = dds_create_writer(r->pub, t->topic, q, NULL);
  dds_delete_qos(q);
  if (t->writer < 0)
    return verr_set(err, "topic %s: cannot create a writer with the recorded QoS: %s", t->name,
                    dds_strretcode(t->writer));
  return 0;
}

static int setup_topics(replay_t *r, verr_t *err) {
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
    rp_topic_t *n = realloc(r->topics, (r->ntopics + 1) * sizeof *n);
    if (!n) break;
    r->topics = n;
    rp_topic_t *t = &r->topics[r->ntopics];
    memset(t, 0, sizeof *t);
    verr_t e;
    if (setup_topic(r, st, t, &e) < 0) {
      fprintf(stderr, "replay: NOT replayed: %s\n", e.msg);
      if (t->writer > 0) dds_delete(t->writer);
      if (t->topic > 0) dds_delete(t->topic);
      topic_free(t);
      continue;
    }
    r->ntopics++;
  }
  if (rc != SQLITE_DONE && rc != SQLITE_ROW)
    fprintf(stderr, "replay: %s: topic table partly unreadable: %s\n", r->path, sqlite3_errmsg(r->db));
  sqlite3_finalize(st);
  if (r->ntopics == 0) return verr_set(err, "%s: no topic could be set up for replay", r->path);
  return 0;
}

static rp_topic_t *topic_by_id(replay_t *r, int64_t id) {
  for (size_t i = 0; i < r->ntopics; i++)
    if (r->topics[i].id == id) return &r->topics[i];
  return NULL;
}

/* Checks the stored bytes against the type and writes them with their
 * source timestamp. Returns true when written. */
static bool publish(replay_t *r, rp_topic_t *t, const recfile_row_t *row) {
  if (row->cdr_len < 4 || row->cdr_len > UINT32_MAX) return false;
  const unsigned char *hdr = row->cdr;
  /* Encapsulation identifier: CDR_BE/LE 0,1; PL_CDR 2,3: XCDR1; CDR2 6,7,
   * D_CDR2 8,9, PL_CDR2 10,11: XCDR2. The low bit says little-endian. */
  if (hdr[0] != 0 || hdr[1] > 11 || hdr[1] == 4 || hdr[1] == 5) return false;
  uint32_t xcdrv = hdr[1] >= 6 ? 2u : 1u;
  bool little = (hdr[1] & 1) != 0;
  uint32_t size = (uint32_t)row->cdr_len - 4;
  if (r->bufcap < row->cdr_len) {
    size_t cap = row->cdr_len + 64;
    unsigned char *b = realloc(r->buf, cap);
    if (!b) return false;
    r->buf = b;
    r->bufcap = cap;
  }
  memcpy(r->buf, (const unsigned char *)row->cdr + 4, size);
  bool just_key = row->kind != REC_KIND_DATA && !row->inferred;
  uint32_t actual = 0;
#if __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  bool bswap = !little;
#else
  bool bswap = little;
#endif
  if (!dds_stream_normalize(r->buf, size, bswap, xcdrv, &t->st, just_key, &actual)) return false;
  dds_time_t ts = row->source_ts_ns > 0 ? row->source_ts_ns : dds_time();
  if (!row->inferred) {
    /* The stored bytes themselves, with their timestamp and status. */
    replay_serdata_status_t status = row->kind == REC_KIND_DATA      ? RSD_DATA
                                     : row->kind == REC_KIND_DISPOSE ? RSD_DISPOSE
                                                                     : RSD_UNREGISTER;
    return replay_serdata_forward(t->writer, row->cdr, row->cdr_len, just_key, status, ts) == DDS_RETCODE_OK;
  }
  /* Inferred end of an instance: the row holds a full sample, but a dispose
   * or unregister goes out key-only; decode and let the writer do that. */
  void *sample = calloc(1, t->st.type.size);
  if (!sample) return false;
  dds_istream_t is;
  dds_istream_init(&is, actual, r->buf, xcdrv);
  if (just_key)
    dds_stream_read_key(&is, sample, &t->st);
  else
    dds_stream_read_sample(&is, sample, &t->st);
  dds_istream_fini(&is);
  dds_return_t rc;
  switch (row->kind) {
  case REC_KIND_DATA:
    rc = dds_write_ts(t->writer, sample, ts);
    break;
  case REC_KIND_DISPOSE:
    rc = dds_dispose_ts(t->writer, sample, ts);
    break;
  default:
    rc = dds_unregister_instance_ts(t->writer, sample, ts);
    break;
  }
  dds_stream_free_sample(sample, t->ops);
  free(sample);
  return rc == DDS_RETCODE_OK;
}

static void progress(replay_t *r, bool force) {
  int64_t now = mono_ns();
  if (r->quiet || (!force && now - r->last_progress < DDS_SECS(1))) return;
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
  if (r->quiet) return;
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
  if (ts > r->sched_ts) r->sched_ts = ts;
  int64_t rel = r->sched_ts - r->t0;
  int64_t seek_ns = (int64_t)(r->seek * 1e9);
  if (rel < seek_ns) {
    /* Skipped time: state (transient-local) topics are still written so
     * receivers start from the right state; streams are dropped. */
    if (!t->transient_local) {
      r->total_skipped++;
      return 0;
    }
  } else {
    int64_t pause_ns = (int64_t)(r->pause_at * 1e9);
    if (r->pause_at >= 0 && !r->pause_at_done && rel >= pause_ns) {
      /* Pause exactly at recording time S, not at the next sample's. */
      r->pause_at_done = true;
      int64_t at = pause_ns > seek_ns ? pause_ns : seek_ns;
      if (!sleep_until(r, r->start_mono + (int64_t)((double)(at - seek_ns) / r->speed))) return 1;
      set_paused(r, true, "--pause-at");
      progress(r, true);
    }
    int64_t due = r->start_mono + (int64_t)((double)(rel - seek_ns) / r->speed);
    if (!sleep_until(r, due)) return 1;
  }
  if (publish(r, t, row)) {
    t->written++;
    r->total_written++;
  } else {
    t->bad++;
    r->total_bad++;
  }
  progress(r, false);
  return 0;
}

static void find_time_range(replay_t *r) {
  const recfile_session_t *s = recfile_session(r->rf);
  sqlite3_stmt *st = NULL;
  int64_t first = 0, last = 0;
  if (sqlite3_prepare_v2(r->db, "SELECT min(source_ts_ns), max(source_ts_ns) FROM samples WHERE kind = 0", -1, &st,
                         NULL) == SQLITE_OK &&
      sqlite3_step(st) == SQLITE_ROW) {
    first = sqlite3_column_int64(st, 0);
    last = sqlite3_column_int64(st, 1);
  }
  sqlite3_finalize(st);
  /* Sim time 0 is the session start (keyframes taken as a late joiner are
   * older and go out at once); without a session row, the first sample. */
  r->t0 = s->valid && s->start_wall_ns > 0 ? s->start_wall_ns : first;
  if (first > 0 && (r->t0 <= 0 || first > r->t0 + DDS_SECS(3600))) r->t0 = first;
  r->t_end = last;
}

/* Opens the recording (and a second read-only connection for the
 * descriptor columns recfile does not expose) and fills in the recorded
 * domain and partition where none was given. Returns 0, or 1 after a
 * message. */
static int open_recording(replay_t *r) {
  verr_t err;
  if (recfile_open(&r->rf, r->path, &err) < 0) {
    fprintf(stderr, "replay: %s\n", err.msg);
    return 1;
  }
  const char *w = recfile_warnings(r->rf);
  if (*w) fprintf(stderr, "replay: %s: %s\n", r->path, w);
  if (recfile_damaged(r->rf)) fprintf(stderr, "replay: %s: damaged; replaying what can be read\n", r->path);
  /* A second read-only connection for the descriptor columns recfile does
   * not expose. */
  if (sqlite3_open_v2(r->path, &r->db, SQLITE_OPEN_READONLY, NULL) != SQLITE_OK) {
    fprintf(stderr, "replay: %s: cannot open: %s\n", r->path, r->db ? sqlite3_errmsg(r->db) : "?");
    sqlite3_close(r->db);
    recfile_close(r->rf);
    return 1;
  }
  sqlite3_busy_timeout(r->db, 2000);
  if (recfile_damaged(r->rf)) sqlite3_exec(r->db, "PRAGMA writable_schema=ON", NULL, NULL, NULL);
  const recfile_session_t *s = recfile_session(r->rf);
  if (r->domain < 0) r->domain = s->valid ? s->domain : 0;
  if (!r->partition[0]) {
    if (!s->valid || strpbrk(s->partition, "*?[") != NULL) {
      fprintf(stderr, "replay: %s: recorded partition '%s' is a pattern or unknown; give --partition\n", r->path,
              s->valid ? s->partition : "");
      sqlite3_close(r->db);
      recfile_close(r->rf);
      return 1;
    }
    snprintf(r->partition, sizeof r->partition, "%s", s->partition);
  }
  return 0;
}

/* Publishes the recording (every pass with --loop) and prints the
 * summary. Returns the exit code. */
static int replay_run(replay_t *r) {
  verr_t err;
  int status = 0;
  dds_qos_t *ppq = vdds_participant_qos();
  r->pp = dds_create_participant((dds_domainid_t)r->domain, ppq, NULL);
  if (ppq) dds_delete_qos(ppq);
  if (r->pp < 0) {
    fprintf(stderr, "replay: cannot create a participant on domain %d: %s\n", r->domain, dds_strretcode(r->pp));
    status = 1;
    goto out;
  }
  dds_qos_t *pq = dds_create_qos();
  dds_qset_partition1(pq, r->partition);
  r->pub = dds_create_publisher(r->pp, pq, NULL);
  dds_delete_qos(pq);
  if (r->pub < 0) {
    fprintf(stderr, "replay: cannot create a publisher: %s\n", dds_strretcode(r->pub));
    status = 1;
    goto out;
  }
  if (setup_topics(r, &err) < 0) {
    fprintf(stderr, "replay: %s\n", err.msg);
    status = 1;
    goto out;
  }
  find_time_range(r);
  vsignal_on_stop(on_signal, 0);
  {
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_usr1;
    sa.sa_flags = SA_RESTART;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGUSR1, &sa, NULL);
  }
  if (!r->quiet)
    fprintf(stderr, "replay: %s: %zu topics into domain %d partition '%s' at speed %g\n", r->path, r->ntopics,
            r->domain, r->partition, r->speed);
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
      fprintf(stderr, "replay: %s: damaged sample table: %s%s; %llu samples read\n", r->path, rep.first_error,
              rep.gave_up ? " (gave up past it)" : "", (unsigned long long)rep.rows);
    if (r->pass_rows == 0) break;
  } while (r->loop && !stop_flag);
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
  printf("SUMMARY written=%llu topics=%zu bad=%llu skipped=%llu\n", (unsigned long long)r->total_written, r->ntopics,
         (unsigned long long)r->total_bad, (unsigned long long)r->total_skipped);
out:
  if (r->pp > 0) dds_delete(r->pp);
  for (size_t i = 0; i < r->ntopics; i++) topic_free(&r->topics[i]);
  free(r->topics);
  free(r->buf);
  sqlite3_close(r->db);
  recfile_close(r->rf);
  return status;
}

int main(int argc, char **argv) {
  vdds_set_role("replay"); /* announced in the participant USER_DATA */
  static replay_t r;
  int rc = parse_args(&r, argc, argv);
  if (rc != CLI_RUN) return rc;
  if (open_recording(&r)) return 1;
  return replay_run(&r);
}
