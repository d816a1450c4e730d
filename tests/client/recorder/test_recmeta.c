/* SPDX-License-Identifier: Apache-2.0 */
/* Session metadata pieces of issue 6 that are pure or file-only:
 * - the participant announcement (common/dds/vdds_ident): format, bounds,
 *   sanitizing of hostile USER_DATA, role extraction;
 * - the replay pause schedule shift (client/recorder/replay_pause);
 * - the participants table: written by the store, read back by recfile,
 *   re-sanitized on read, and absent (old recordings) without error. */
#include <stdint.h>
#include <string.h>
#include <unistd.h>

#include <sqlite3.h>

#include "check.h"
#include "dds/vdds_ident.h"
#include "recording/recfile.h"
#include "recording/store.h"
#include "replay_pause.h"

static void test_format_and_role(void) {
  char buf[VDDS_IDENT_MAX], role[VDDS_ROLE_MAX];
  size_t n = vdds_ident_format(buf, sizeof buf, "haptic", 2, "lab-pc", 1234);
  CHECK(strcmp(buf, "viscera role=haptic tool=2 host=lab-pc pid=1234") == 0);
  CHECK(n == strlen(buf));
  CHECK(vdds_ident_role(buf, role, sizeof role) == 0 && strcmp(role, "haptic") == 0);
  vdds_ident_format(buf, sizeof buf, "server", -1, "h", 7);
  CHECK(strcmp(buf, "viscera role=server host=h pid=7") == 0);
  /* bounded: a small buffer truncates, still terminated */
  char small[16];
  n = vdds_ident_format(small, sizeof small, "server", -1, "h", 7);
  CHECK(n == 15 && strlen(small) == 15 && strncmp(small, "viscera role=se", 15) == 0);
  /* a hostile hostname cannot inject control characters */
  vdds_ident_format(buf, sizeof buf, "viewer", -1, "evil\n\x1b[2J", 1);
  CHECK(strchr(buf, '\n') == NULL && strchr(buf, 0x1b) == NULL);
  /* role token must be ours: other text, no role, empty role, truncation */
  CHECK(vdds_ident_role("something else role=server", role, sizeof role) == -1 && role[0] == 0);
  CHECK(vdds_ident_role("viscera host=x pid=1", role, sizeof role) == -1);
  CHECK(vdds_ident_role("viscera xrole=server", role, sizeof role) == -1);
  CHECK(vdds_ident_role("viscera role= host=x", role, sizeof role) == -1);
  char r4[4];
  CHECK(vdds_ident_role("viscera role=dashboard", r4, sizeof r4) == 0 && strcmp(r4, "das") == 0);
  /* the role setter keeps one token */
  vdds_set_role("bad role=x\n");
  CHECK(strcmp(vdds_role(), "bad_role_x_") == 0);
  vdds_set_role(NULL);
  CHECK(strcmp(vdds_role(), "unknown") == 0);
  char longrole[100];
  memset(longrole, 'r', sizeof longrole - 1);
  longrole[sizeof longrole - 1] = 0;
  vdds_set_role(longrole);
  CHECK(strlen(vdds_role()) == VDDS_ROLE_MAX - 1);
  vdds_set_role("recorder");
  vdds_ident_self(buf, sizeof buf);
  CHECK(strncmp(buf, "viscera role=recorder host=", 27) == 0);
}

static void test_sanitize(void) {
  char out[8];
  const unsigned char bin[] = {'a', 0x01, 0xff, 'b', '\t', 'c'};
  CHECK(vdds_ident_sanitize(out, sizeof out, bin, sizeof bin) == 6);
  CHECK(strcmp(out, "a??b?c") == 0);
  /* stops at NUL, bounded by cap, NULL input */
  CHECK(vdds_ident_sanitize(out, sizeof out, "ab\0cd", 5) == 2 && strcmp(out, "ab") == 0);
  CHECK(vdds_ident_sanitize(out, sizeof out, "0123456789", 10) == 7 && strcmp(out, "0123456") == 0);
  CHECK(vdds_ident_sanitize(out, sizeof out, NULL, 10) == 0 && out[0] == 0);
  CHECK(vdds_ident_sanitize(out, 0, "x", 1) == 0);
}

static void test_pause_shift(void) {
  const int64_t S = 1000000000;
  rpause_t p = {0};
  CHECK(rpause_due(&p, 5 * S) == 5 * S);
  rpause_set(&p, true, 1 * S); /* pause at 1 s */
  CHECK(p.paused && rpause_due(&p, 1 * S) == INT64_MAX);
  rpause_set(&p, true, 2 * S); /* pausing again changes nothing */
  CHECK(p.since == 1 * S);
  rpause_set(&p, false, 3 * S); /* resume after 2 s */
  /* a sample due at 1.5 s (missed while paused) goes at 3.5 s, not at once:
   * the spacing after resume is the recorded one */
  CHECK(rpause_due(&p, 3 * S / 2) == 7 * S / 2);
  CHECK(rpause_due(&p, 2 * S) - rpause_due(&p, 3 * S / 2) == S / 2);
  rpause_toggle(&p, 4 * S);
  rpause_toggle(&p, 4 * S + S / 2); /* second pause, 0.5 s */
  CHECK(p.shift == 2 * S + S / 2);
  rpause_set(&p, false, 5 * S); /* resume when running: no-op */
  CHECK(p.shift == 2 * S + S / 2);
  CHECK(rpause_due(&p, INT64_MAX - 1) == INT64_MAX); /* saturates */
  rpause_toggle(&p, 6 * S);
  rpause_new_pass(&p, 7 * S); /* new pass while paused: shift restarts */
  CHECK(p.paused && p.shift == 0 && p.since == 7 * S);
  rpause_toggle(&p, 8 * S);
  CHECK(rpause_due(&p, 7 * S) == 8 * S);
}

typedef struct seen {
  int n;
  recfile_participant_t p[4];
} seen_t;
static void collect(void *arg, const recfile_participant_t *p) {
  seen_t *s = arg;
  if (s->n < 4) s->p[s->n] = *p;
  s->n++;
}

static void test_table(void) {
  char path[128];
  snprintf(path, sizeof path, "/tmp/viscera_test_%d_recmeta.db", (int)getpid());
  verr_t err = {{0}};
  store_t *s = NULL;
  store_session_t meta = {"unit", "viscera/unit", 42, 1700000000000000000LL, "host", "test"};
  CHECK(store_open(&s, path, true, &meta, &err) == 0);
  if (!s) return;
  uint8_t g1[16] = {1}, g2[16] = {2};
  CHECK(store_note_participant(s, g1, "viscera role=server host=a pid=1", "server", false, 100, &err) == 0);
  CHECK(store_note_participant(s, g2, "viscera role=haptic tool=0 host=a pid=2", "haptic", false, 200, &err) == 0);
  CHECK(store_note_participant(s, g2, NULL, NULL, true, 300, &err) == 0); /* left */
  CHECK(store_note_participant(s, g1, "viscera role=server host=a pid=1", "server", false, 250, &err) ==
        0); /* update */
  CHECK(store_close(s, 1000, &err) == 0);

  recfile_t *rf = NULL;
  CHECK(recfile_open(&rf, path, &err) == 0);
  seen_t seen = {0};
  CHECK(recfile_participants(rf, collect, &seen) == 2);
  CHECK(seen.n == 2);
  CHECK(strcmp(seen.p[0].role, "server") == 0 && seen.p[0].first_seen_wall_ns == 100);
  CHECK(seen.p[0].left_wall_ns < 0 && seen.p[0].last_seen_wall_ns == 1000); /* present until the end */
  CHECK(strcmp(seen.p[1].role, "haptic") == 0 && seen.p[1].left_wall_ns == 300 && seen.p[1].last_seen_wall_ns == 300);
  CHECK(strcmp(seen.p[0].guid, "01000000000000000000000000000000") == 0);
  recfile_close(rf);

  /* a tampered file: control characters and an oversized text are cleaned
   * on read, not trusted */
  sqlite3 *db = NULL;
  CHECK(sqlite3_open(path, &db) == SQLITE_OK);
  CHECK(sqlite3_exec(db,
                     "UPDATE participants SET user_data = char(27) || '[2Jx' || zeroblob(0) || hex(zeroblob(400)),"
                     " role = 'a' || char(10) || 'b' WHERE role = 'server'",
                     NULL, NULL, NULL) == SQLITE_OK);
  sqlite3_close(db);
  rf = NULL;
  CHECK(recfile_open(&rf, path, &err) == 0);
  memset(&seen, 0, sizeof seen);
  CHECK(recfile_participants(rf, collect, &seen) == 2);
  CHECK(strcmp(seen.p[0].role, "a?b") == 0);
  CHECK(seen.p[0].user_data[0] == '?' && strlen(seen.p[0].user_data) == sizeof seen.p[0].user_data - 1);
  recfile_close(rf);

  /* a recording from before the table existed reads, without participants */
  CHECK(sqlite3_open(path, &db) == SQLITE_OK);
  CHECK(sqlite3_exec(db, "DROP TABLE participants", NULL, NULL, NULL) == SQLITE_OK);
  sqlite3_close(db);
  rf = NULL;
  CHECK(recfile_open(&rf, path, &err) == 0);
  memset(&seen, 0, sizeof seen);
  CHECK(recfile_participants(rf, collect, &seen) == -1 && seen.n == 0);
  recfile_close(rf);
  unlink(path);
}

int main(void) {
  test_format_and_role();
  test_sanitize();
  test_pause_shift();
  test_table();
  return check_report("test_recmeta");
}
