/* SPDX-License-Identifier: Apache-2.0 */
/* rec_decode (common/recording/rec_decode.h) in a LATER build whose types
 * have grown (grown_types.idl: a field appended to SessionEvent, to
 * ToolCommand and to SceneSource): every SessionEvent and ToolCommand of the
 * format-1 recording kept in tests/data (final types, XCDR1) still decodes,
 * through the frozen twin idl/viscera_format1.idl, with its recorded values
 * and the appended field zero; without the twin none would (a shorter XCDR1
 * sample does not normalize against the grown type). The SceneSource of the
 * format-2 recording (a resumed session) decodes through
 * idl/viscera_format2.idl with its resume state whole: read with the
 * format-1 twin it would decode too, without it (trailing bytes are
 * ignored), so the newest twin must come first. The format-3 recording
 * (@appendable types, XCDR2) needs no twin: its samples decode with the
 * grown types themselves, the appended fields at their default (0), which is
 * what @appendable promises a later build. Needs VISCERA_SOURCE_DIR. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "grown_types.h"
#include "recording/rec_decode.h"

typedef struct tally {
  int events, texts, commands, seqs, grown;
} tally_t;

static int on_event(void *arg, const void *sample, const recfile_row_t *row) {
  (void)row;
  tally_t *t = arg;
  const viscera_SessionEvent *e = sample;
  t->events++;
  if (e->text[0] && e->seq > 0) t->texts++;
  if (e->grown_id) t->grown++;
  return 0;
}

static int on_command(void *arg, const void *sample, const recfile_row_t *row) {
  (void)row;
  tally_t *t = arg;
  const viscera_ToolCommand *c = sample;
  t->commands++;
  if (c->seq > 0 && c->max_force > 0 && c->orientation[0] != 0) t->seqs++;
  if (c->grown_seq) t->grown++;
  return 0;
}

typedef struct source_tally {
  int n, have_text;
  uint32_t resume_len;
  char resume_sha256[65];
  uint64_t grown;
} source_tally_t;

static int on_source(void *arg, const void *sample, const recfile_row_t *row) {
  (void)row;
  source_tally_t *t = arg;
  const viscera_SceneSource *s = sample;
  t->n++;
  t->have_text = s->text && strstr(s->text, "organs:") != NULL;
  t->resume_len = s->resume_state._length;
  snprintf(t->resume_sha256, sizeof t->resume_sha256, "%s", s->resume_sha256);
  t->grown = s->grown_source;
  return 0;
}

static void source_of(const char *src, const char *file, source_tally_t *t) {
  char path[1024];
  snprintf(path, sizeof path, "%s/tests/data/%s", src ? src : ".", file);
  recfile_t *rf = NULL;
  verr_t err;
  memset(t, 0, sizeof *t);
  CHECK(recfile_open(&rf, path, &err) == 0);
  if (!rf) return;
  rec_decode_report_t rep;
  CHECK(rec_decode_topic(rf, "viscera_SceneSource", &viscera_SceneSource_desc, on_source, t, &rep) == 0);
  CHECK(rep.undecodable == 0 && rep.decoded == 1);
  recfile_close(rf);
}

int main(void) {
  const char *src = getenv("VISCERA_SOURCE_DIR");
  char path[1024];
  snprintf(path, sizeof path, "%s/tests/data/session_applied_xcdr1.db", src ? src : ".");
  recfile_t *rf = NULL;
  verr_t err;
  CHECK(recfile_open(&rf, path, &err) == 0);
  if (!rf) {
    fprintf(stderr, "%s\n", err.msg);
    return 1;
  }
  tally_t t = {0};
  rec_decode_report_t rep;
  CHECK(rec_decode_topic(rf, "viscera_SessionEvent", &viscera_SessionEvent_desc, on_event, &t, &rep) == 0);
  CHECK(rep.undecodable == 0 && rep.decoded == 11);
  CHECK(rec_decode_topic(rf, "viscera_ToolCommand", &viscera_ToolCommand_desc, on_command, &t, &rep) == 0);
  CHECK(rep.undecodable == 0 && rep.decoded == 251);
  CHECK(t.events == 11 && t.texts == 11);
  CHECK(t.commands == 251 && t.seqs == 251);
  CHECK(t.grown == 0);
  recfile_close(rf);

  /* format 3: XCDR2 samples of the @appendable types, read by the grown ones directly */
  snprintf(path, sizeof path, "%s/tests/data/session_appendable_format3.db", src ? src : ".");
  CHECK(recfile_open(&rf, path, &err) == 0);
  if (rf) {
    tally_t t3 = {0};
    CHECK(rec_decode_topic(rf, "viscera_SessionEvent", &viscera_SessionEvent_desc, on_event, &t3, &rep) == 0);
    CHECK(rep.undecodable == 0 && rep.decoded == 7);
    CHECK(rec_decode_topic(rf, "viscera_ToolCommand", &viscera_ToolCommand_desc, on_command, &t3, &rep) == 0);
    CHECK(rep.undecodable == 0 && rep.decoded == 251);
    CHECK(t3.events == 7 && t3.texts == 7 && t3.commands == 251 && t3.seqs == 251 && t3.grown == 0);
    recfile_close(rf);
  }
  source_tally_t s1, s2, s3;
  source_of(src, "session_appendable_format3.db", &s3);
  CHECK(s3.n == 1 && s3.have_text && s3.resume_len == 0 && s3.grown == 0);
  source_of(src, "session_applied_xcdr1.db", &s1); /* format 1: no resume fields */
  CHECK(s1.n == 1 && s1.have_text && s1.resume_len == 0 && s1.resume_sha256[0] == 0 && s1.grown == 0);
  source_of(src, "session_resumed_format2.db", &s2); /* format 2: resumed, its state whole */
  CHECK(s2.n == 1 && s2.have_text && s2.resume_len == 96224 && strlen(s2.resume_sha256) == 64 && s2.grown == 0);
  return check_report("test_rec_decode_grown");
}
