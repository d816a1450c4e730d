/* SPDX-License-Identifier: Apache-2.0 */
/* rec_check: verifies a recording made of rec_pub's session, straight from
 * the SQLite file (independent of viscera-recinfo):
 *   - session row: partition, domain, end time written;
 *   - topics ToolCommand, MeshDelta and MeshState, with the descriptor
 *     the recorder discovered at run time equal to the compiled-in one;
 *   - the MeshState keyframes written before the recorder started;
 *   - every ToolCommand, and per writer non-decreasing source timestamps;
 *   - the MeshDelta dispose of REC_TEST_DISPOSED_ORGAN stored as a dispose;
 *   - the stored CDR of every ToolCommand decodes, with the compiled-in
 *     descriptor, to exactly what rec_pub published.
 * usage: rec_check FILE.db TOOLS DELTAS PARTITION DOMAIN */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <dds/dds.h>
#include <dds/ddsi/ddsi_cdrstream.h>
#include <sqlite3.h>

#include "check.h"
#include "recording/rec_decode.h"
#include "rec_values.h"
#include "viscera.h"

static sqlite3 *db;

static int64_t q_int(const char *sql, const char *arg) {
  sqlite3_stmt *st = NULL;
  int64_t v = -1;
  if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) != SQLITE_OK) {
    fprintf(stderr, "rec_check: %s: %s\n", sql, sqlite3_errmsg(db));
    return -1;
  }
  if (arg) sqlite3_bind_text(st, 1, arg, -1, SQLITE_STATIC);
  if (sqlite3_step(st) == SQLITE_ROW && sqlite3_column_type(st, 0) != SQLITE_NULL) v = sqlite3_column_int64(st, 0);
  sqlite3_finalize(st);
  return v;
}

static void check_descriptor(const char *topic, const dds_topic_descriptor_t *d) {
  sqlite3_stmt *st = NULL;
  sqlite3_prepare_v2(db,
                     "SELECT type_name, desc_size, desc_align, desc_flagset, nkeys, nops, ops FROM topics"
                     " WHERE name=?1",
                     -1, &st, NULL);
  sqlite3_bind_text(st, 1, topic, -1, SQLITE_STATIC);
  CHECK(sqlite3_step(st) == SQLITE_ROW);
  if (sqlite3_column_type(st, 0) == SQLITE_NULL) {
    sqlite3_finalize(st);
    return;
  }
  CHECK(strcmp((const char *)sqlite3_column_text(st, 0), d->m_typename) == 0);
  CHECK(sqlite3_column_int64(st, 1) == d->m_size);
  CHECK(sqlite3_column_int64(st, 2) == d->m_align);
  CHECK(sqlite3_column_int64(st, 4) == d->m_nkeys);
  uint32_t nops = dds_stream_countops(d->m_ops, d->m_nkeys, d->m_keys);
  CHECK(sqlite3_column_int64(st, 5) == nops);
  const unsigned char *ops = sqlite3_column_blob(st, 6);
  CHECK(sqlite3_column_bytes(st, 6) == (int)(4 * nops));
  bool same = ops != NULL && sqlite3_column_bytes(st, 6) == (int)(4 * nops);
  for (uint32_t i = 0; same && i < nops; i++) {
    uint32_t w = (uint32_t)ops[4 * i] | (uint32_t)ops[4 * i + 1] << 8 | (uint32_t)ops[4 * i + 2] << 16 |
                 (uint32_t)ops[4 * i + 3] << 24;
    if (w != d->m_ops[i]) same = false;
  }
  CHECK(same);
  if (!same) fprintf(stderr, "rec_check: %s: stored ops differ from the compiled-in descriptor\n", topic);
  sqlite3_finalize(st);
}

/* Field by field: the struct has padding, so memcmp would compare garbage. */
static bool same_tool_command(const viscera_ToolCommand *a, const viscera_ToolCommand *b) {
  if (a->tool_id != b->tool_id || a->seq != b->seq || a->client_mono_ns != b->client_mono_ns ||
      a->buttons != b->buttons || a->max_force != b->max_force)
    return false;
  for (int i = 0; i < 3; i++)
    if (a->position[i] != b->position[i]) return false;
  for (int i = 0; i < 4; i++)
    if (a->orientation[i] != b->orientation[i]) return false;
  return true;
}

/* Per writer, data-sample source timestamps must not decrease in insertion
 * order (key-only rows may carry an instance's older update time). */
static void check_monotonic(const char *topic) {
  sqlite3_stmt *st = NULL;
  sqlite3_prepare_v2(db,
                     "SELECT s.writer_id, s.source_ts_ns FROM samples s JOIN topics t ON t.id = s.topic_id"
                     " WHERE t.name=?1 AND s.kind=0 ORDER BY s.writer_id, s.id",
                     -1, &st, NULL);
  sqlite3_bind_text(st, 1, topic, -1, SQLITE_STATIC);
  int64_t prev_w = -1, prev_ts = 0, decreases = 0, null_writers = 0;
  while (sqlite3_step(st) == SQLITE_ROW) {
    if (sqlite3_column_type(st, 0) == SQLITE_NULL) {
      null_writers++;
      continue;
    }
    int64_t w = sqlite3_column_int64(st, 0), ts = sqlite3_column_int64(st, 1);
    if (w == prev_w && ts < prev_ts) decreases++;
    prev_w = w;
    prev_ts = ts;
  }
  sqlite3_finalize(st);
  CHECK(decreases == 0);
  CHECK(null_writers == 0);
  if (decreases || null_writers)
    fprintf(stderr, "rec_check: %s: %lld decreases, %lld samples without writer\n", topic, (long long)decreases,
            (long long)null_writers);
}

int main(int argc, char **argv) {
  if (argc != 6) {
    fprintf(stderr, "usage: rec_check FILE.db TOOLS DELTAS PARTITION DOMAIN\n");
    return 2;
  }
  const long tools = atol(argv[2]), deltas = atol(argv[3]);
  if (sqlite3_open_v2(argv[1], &db, SQLITE_OPEN_READONLY, NULL) != SQLITE_OK) {
    fprintf(stderr, "rec_check: %s: %s\n", argv[1], sqlite3_errmsg(db));
    return 1;
  }

  /* session */
  CHECK(q_int("SELECT count(*) FROM session WHERE partition=?1", argv[4]) == 1);
  CHECK(q_int("SELECT domain FROM session", NULL) == atol(argv[5]));
  CHECK(q_int("SELECT end_wall_ns > start_wall_ns FROM session", NULL) == 1);

  /* topics and their run-time descriptors */
  check_descriptor("viscera_ToolCommand", &viscera_ToolCommand_desc);
  check_descriptor("viscera_MeshDelta", &viscera_MeshDelta_desc);
  check_descriptor("viscera_MeshState", &viscera_MeshState_desc);
  CHECK(q_int("SELECT reliability='best_effort' AND durability='volatile' FROM topics WHERE name=?1",
              "viscera_ToolCommand") == 1);
  CHECK(q_int("SELECT reliability='reliable' AND durability='transient_local' FROM topics WHERE name=?1",
              "viscera_MeshState") == 1);

  const char *count_kind =
      "SELECT count(*) FROM samples s JOIN topics t ON t.id=s.topic_id WHERE t.name=?1 AND s.kind=";
  char sql[256];

  /* late-join keyframes: both organs, written before the session started */
  snprintf(sql, sizeof sql, "%s0", count_kind);
  int64_t keyframes = q_int(sql, "viscera_MeshState");
  CHECK(keyframes == 2);
  CHECK(q_int("SELECT count(*) FROM samples s JOIN topics t ON t.id=s.topic_id, session"
              " WHERE t.name=?1 AND s.kind=0 AND s.source_ts_ns < session.start_wall_ns",
              "viscera_MeshState") == 2);

  /* streams */
  int64_t n_tools = q_int(sql, "viscera_ToolCommand");
  int64_t n_deltas = q_int(sql, "viscera_MeshDelta");
  CHECK(n_tools == tools);
  CHECK(n_deltas == deltas);
  printf("rec_check: %lld/%ld ToolCommand, %lld/%ld MeshDelta, %lld MeshState keyframes\n", (long long)n_tools, tools,
         (long long)n_deltas, deltas, (long long)keyframes);
  check_monotonic("viscera_ToolCommand");
  check_monotonic("viscera_MeshDelta");

  /* the dispose, as a dispose, of the right instance (organ_id is the
   * first member, so it is the first 4 payload bytes of a key-only sample
   * and of an XCDR1 sample; an XCDR2 sample of the @appendable type, which
   * a dispose inferred from instance state stores whole, has its DHEADER
   * first: encapsulation D_CDR2, 8 or 9). Organ 0 is disposed too, by the
   * writer's auto-dispose when rec_pub exits, so look for organ 1 among
   * the dispose rows. */
  sqlite3_stmt *st = NULL;
  sqlite3_prepare_v2(db,
                     "SELECT s.cdr, s.inferred FROM samples s JOIN topics t ON t.id=s.topic_id"
                     " WHERE t.name='viscera_MeshDelta' AND s.kind=1 ORDER BY s.id",
                     -1, &st, NULL);
  int disposes_of_organ = 0;
  while (sqlite3_step(st) == SQLITE_ROW) {
    const unsigned char *b = sqlite3_column_blob(st, 0);
    int n = sqlite3_column_bytes(st, 0);
    CHECK(n >= 8);
    if (n < 8) continue;
    int at = sqlite3_column_int(st, 1) && (b[1] == 8 || b[1] == 9) ? 8 : 4;
    CHECK(n >= at + 4);
    if (n < at + 4) continue;
    const unsigned char *k = b + at; /* organ_id */
    uint32_t organ = (b[1] & 1) ? (uint32_t)k[0] | (uint32_t)k[1] << 8 | (uint32_t)k[2] << 16 | (uint32_t)k[3] << 24
                                : (uint32_t)k[3] | (uint32_t)k[2] << 8 | (uint32_t)k[1] << 16 | (uint32_t)k[0] << 24;
    if (organ == REC_TEST_DISPOSED_ORGAN) {
      disposes_of_organ++;
      printf("rec_check: dispose of organ %u stored (%d bytes, %s)\n", organ, n,
             sqlite3_column_int(st, 1) ? "inferred from instance state" : "key-only sample");
    }
  }
  sqlite3_finalize(st);
  CHECK(disposes_of_organ == 1);

  /* every ToolCommand decodes to what was published, in publication order */
  sqlite3_prepare_v2(db,
                     "SELECT s.cdr FROM samples s JOIN topics t ON t.id=s.topic_id"
                     " WHERE t.name='viscera_ToolCommand' AND s.kind=0 ORDER BY s.id",
                     -1, &st, NULL);
  long decoded = 0, mismatched = 0, undecodable = 0;
  int64_t expect = 0;
  while (sqlite3_step(st) == SQLITE_ROW) {
    viscera_ToolCommand got;
    memset(&got, 0, sizeof got);
    if (!rec_decode_cdr(sqlite3_column_blob(st, 0), (size_t)sqlite3_column_bytes(st, 0), &viscera_ToolCommand_desc,
                        &got)) {
      undecodable++;
      continue;
    }
    decoded++;
    viscera_ToolCommand want = rec_test_tool_command((uint32_t)expect);
    if (!same_tool_command(&got, &want)) {
      if (!mismatched)
        fprintf(stderr, "rec_check: ToolCommand #%lld decoded as seq %llu pos %g,%g buttons %u\n", (long long)expect,
                (unsigned long long)got.seq, got.position[0], got.position[1], got.buttons);
      mismatched++;
    }
    expect++;
  }
  sqlite3_finalize(st);
  CHECK(undecodable == 0);
  CHECK(mismatched == 0);
  CHECK(decoded == tools);
  printf("rec_check: %ld ToolCommand decoded with the compiled-in descriptor, %ld mismatched\n", decoded, mismatched);
  sqlite3_close(db);
  return check_report("rec_check");
}
