/* SPDX-License-Identifier: Apache-2.0 */
/* rec_decode: stored CDR back into the compiled-in types. Serializes
 * samples as a writer does (XCDR2 with delimiters, D_CDR2_LE header: every
 * product type is @appendable), decodes them,
 * and feeds the decoder every kind of bad blob: truncated, garbled, an
 * enum value the type does not have, all zeros, an unknown encoding. Also
 * finds enum values by literal name in the type information, which is how
 * the report tool recognizes event kinds added after it was written. */
#include <stdlib.h>
#include <string.h>

#include <dds/ddsi/ddsi_cdrstream.h>

#include "check.h"
#include "recording/rec_decode.h"
#include "viscera.h"

/* The 4-byte D_CDR2_LE header + payload, as stored; *len set. Caller frees. */
static unsigned char *serialize(const void *sample, const dds_topic_descriptor_t *desc, size_t *len) {
  dds_ostream_t os;
  dds_ostream_init(&os, 0, 2);
  dds_stream_write(&os, sample, desc->m_ops);
  unsigned char *b = malloc(os.m_index + 4);
  b[0] = 0, b[1] = 9, b[2] = 0, b[3] = 0;
  memcpy(b + 4, os.m_buffer, os.m_index);
  *len = os.m_index + 4;
  dds_ostream_fini(&os);
  return b;
}

static void test_event(void) {
  viscera_SessionEvent e;
  memset(&e, 0, sizeof e);
  e.source_id = 0;
  e.seq = 42;
  e.sim_time_ns = 1234567890123ull;
  e.kind = viscera_EVENT_THRESHOLD_CROSSED_UP;
  e.organ_id = 0;
  e.tool_id = 1;
  e.value = 0.8;
  snprintf(e.text, sizeof e.text, "MPF crossed up: tool 'probe' force 0.812 N above 0.800 N");
  size_t len = 0;
  unsigned char *b = serialize(&e, &viscera_SessionEvent_desc, &len);
  viscera_SessionEvent got;
  memset(&got, 0, sizeof got);
  CHECK(rec_decode_cdr(b, len, &viscera_SessionEvent_desc, &got));
  CHECK(got.seq == 42 && got.sim_time_ns == e.sim_time_ns && got.kind == e.kind && got.tool_id == 1 &&
        got.value == 0.8 && strcmp(got.text, e.text) == 0);
  rec_decode_free(&got, &viscera_SessionEvent_desc);

  /* every truncation fails cleanly */
  int truncated_ok = 0;
  for (size_t n = 0; n < len; n++) truncated_ok += rec_decode_cdr(b, n, &viscera_SessionEvent_desc, &got);
  CHECK(truncated_ok == 0);
  /* an enum value past the type's last literal (a newer writer's kind):
   * Cyclone's writer refuses to write one, so the kind's byte is found by
   * writing another valid kind and changed in place */
  viscera_SessionEvent other = e;
  other.kind = viscera_EVENT_KEYFRAME;
  size_t llen = 0, at = 0;
  unsigned char *lb = serialize(&other, &viscera_SessionEvent_desc, &llen);
  CHECK(llen == len);
  while (at < len && lb[at] == b[at]) at++;
  CHECK(at < len && at + 1 < len && lb[at + 1] == b[at + 1]); /* one byte differs: the kind's low byte */
  memcpy(lb, b, len);
  lb[at] = 200;
  CHECK(!rec_decode_cdr(lb, llen, &viscera_SessionEvent_desc, &got));
  lb[at] = (unsigned char)viscera_EVENT_KEYFRAME; /* the same bytes with a known kind decode */
  CHECK(rec_decode_cdr(lb, llen, &viscera_SessionEvent_desc, &got) && got.kind == viscera_EVENT_KEYFRAME);
  rec_decode_free(&got, &viscera_SessionEvent_desc);
  free(lb);
  /* a string length beyond the sample */
  unsigned char *g = malloc(len);
  memcpy(g, b, len);
  /* text length word (XCDR2 aligns 8-byte members to 4): after DHEADER 4, source_id 4, seq 8, sim 8,
   * kind 4, organ 4, tool 4, value 8 = 44 */
  CHECK(b[4 + 44] == strlen(e.text) + 1);
  g[4 + 44] = 0xff, g[4 + 45] = 0xff;
  CHECK(!rec_decode_cdr(g, len, &viscera_SessionEvent_desc, &got));
  /* unknown encoding identifier, and a zero-filled blob */
  memcpy(g, b, len);
  g[1] = 0x20;
  CHECK(!rec_decode_cdr(g, len, &viscera_SessionEvent_desc, &got));
  memset(g, 0, len);
  CHECK(!rec_decode_cdr(g, len, &viscera_SessionEvent_desc, &got));
  /* random bytes behind a valid header: no crash, whatever the verdict */
  srand(7);
  for (int k = 0; k < 2000; k++) {
    memcpy(g, b, 4);
    for (size_t i = 4; i < len; i++) g[i] = (unsigned char)rand();
    if (rec_decode_cdr(g, len, &viscera_SessionEvent_desc, &got)) rec_decode_free(&got, &viscera_SessionEvent_desc);
  }
  free(g);
  free(b);
}

/* Sequences are allocated by the decoder and released by rec_decode_free
 * (the sanitizer build checks nothing leaks). */
static void test_scene_info(void) {
  viscera_SceneInfo si;
  memset(&si, 0, sizeof si);
  snprintf(si.scene, sizeof si.scene, "kidney-palpation");
  si.physics_dt = 0.001;
  viscera_ToolInfo tools[2];
  memset(tools, 0, sizeof tools);
  tools[0].tool_id = 0, tools[0].st = 0.5f, tools[0].mpf = 0.8f, tools[0].sft = 1.5f;
  snprintf(tools[0].name, sizeof tools[0].name, "probe");
  tools[1].tool_id = 1;
  snprintf(tools[1].name, sizeof tools[1].name, "grasper");
  si.tools._buffer = tools;
  si.tools._length = si.tools._maximum = 2;
  size_t len = 0;
  unsigned char *b = serialize(&si, &viscera_SceneInfo_desc, &len);
  viscera_SceneInfo got;
  memset(&got, 0, sizeof got);
  for (int rep = 0; rep < 3; rep++) { /* the buffer is reusable after free */
    CHECK(rec_decode_cdr(b, len, &viscera_SceneInfo_desc, &got));
    CHECK(got.tools._length == 2 && got.tools._buffer && got.tools._buffer[0].mpf == 0.8f &&
          strcmp(got.tools._buffer[1].name, "grasper") == 0 && got.organs._length == 0);
    rec_decode_free(&got, &viscera_SceneInfo_desc);
    CHECK(got.tools._buffer == NULL);
  }
  /* Into a buffer full of garbage (an uninitialized local, as viscera-resim
   * passes): the decoder zeroes it first instead of reusing or freeing the
   * garbage sequence pointers. A failed decode leaves it zeroed. */
  memset(&got, 0xA5, sizeof got);
  CHECK(rec_decode_cdr(b, len, &viscera_SceneInfo_desc, &got));
  CHECK(got.tools._length == 2 && got.tools._buffer && got.organs._length == 0 && got.organs._buffer == NULL);
  rec_decode_free(&got, &viscera_SceneInfo_desc);
  memset(&got, 0xA5, sizeof got);
  CHECK(!rec_decode_cdr(b, 3, &viscera_SceneInfo_desc, &got));
  CHECK(got.tools._buffer == NULL && got.tools._length == 0 && got.scene[0] == 0);
  free(b);
}

static void test_enum_names(void) {
  int32_t v = -1;
  CHECK(rec_decode_enum_value(&viscera_SessionEvent_desc, "EVENT_THRESHOLD_CROSSED_UP", &v) &&
        v == (int32_t)viscera_EVENT_THRESHOLD_CROSSED_UP);
  CHECK(rec_decode_enum_value(&viscera_SessionEvent_desc, "EVENT_SESSION_STARTED", &v) &&
        v == (int32_t)viscera_EVENT_SESSION_STARTED);
  CHECK(rec_decode_enum_value(&viscera_SessionEvent_desc, "EVENT_KEYFRAME", &v) &&
        v == (int32_t)viscera_EVENT_KEYFRAME);
  CHECK(!rec_decode_enum_value(&viscera_SessionEvent_desc, "EVENT_NO_SUCH_KIND", &v));
  /* a type without enums */
  CHECK(!rec_decode_enum_value(&viscera_ToolCommand_desc, "EVENT_KEYFRAME", &v));
}

int main(void) {
  test_event();
  test_scene_info();
  test_enum_names();
  return check_report("test_rec_decode");
}
