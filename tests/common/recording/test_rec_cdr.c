/* SPDX-License-Identifier: Apache-2.0 */
/* rec_types, rec_idl, rec_cdr: a topic's type rebuilt from its XTypes
 * type information (here the compiled one, as the recorder stores it), its
 * OMG IDL text, and samples serialized as a writer does (XCDR1 and XCDR2,
 * little-endian) decoded into JSON and CSV; every truncation and garbled
 * length is refused with a message, never read out of bounds. */
#include <stdlib.h>
#include <string.h>

#include <dds/ddsi/ddsi_cdrstream.h>

#include "check.h"
#include "recording/rec_cdr.h"
#include "recording/rec_idl.h"
#include "recording/rec_types.h"
#include "viscera.h"

/* Encoding header + payload as stored; xcdr 1 or 2. Caller frees. */
static unsigned char *serialize(const void *sample, const dds_topic_descriptor_t *desc, int xcdr, size_t *len) {
  dds_ostream_t os;
  dds_ostream_init(&os, 0, (uint32_t)xcdr);
  dds_stream_write(&os, sample, desc->m_ops);
  unsigned char *b = malloc(os.m_index + 4);
  b[0] = 0, b[1] = xcdr == 1 ? 1 : 7, b[2] = 0, b[3] = 0;
  memcpy(b + 4, os.m_buffer, os.m_index);
  *len = os.m_index + 4;
  dds_ostream_fini(&os);
  return b;
}

static int load(rt_model_t *m, const dds_topic_descriptor_t *desc, const char *name) {
  verr_t err = {{0}};
  int r = rt_model_load(m, desc->type_mapping.data, desc->type_mapping.sz, name, &err);
  if (r < 0) fprintf(stderr, "%s\n", err.msg);
  return r;
}

static void test_idl(void) {
  rt_model_t m;
  CHECK(load(&m, &viscera_SceneInfo_desc, "viscera::SceneInfo") == 0);
  rt_str_t idl = {0};
  verr_t err = {{0}};
  CHECK(rt_idl_text(&m, &idl, &err) == 0);
  const char *organ = strstr(idl.s, "struct OrganInfo {"), *scene = strstr(idl.s, "struct SceneInfo {");
  CHECK(organ && scene && organ < scene); /* used before it is used */
  CHECK(strstr(idl.s, "module viscera {\n@final\nstruct SceneInfo {\n  string<64> scene;\n"));
  CHECK(strstr(idl.s, "  sequence<viscera::OrganInfo> organs;\n"));
  CHECK(strstr(idl.s, "  float color[3];\n"));
  rt_str_free(&idl);
  rt_model_free(&m);
  CHECK(load(&m, &viscera_SessionEvent_desc, "viscera::SessionEvent") == 0);
  CHECK(rt_idl_text(&m, &idl, &err) == 0);
  CHECK(strstr(idl.s, "enum EventKind {\n  EVENT_SESSION_STARTED,\n"));
  CHECK(strstr(idl.s, "  @key unsigned long source_id;\n  unsigned long long seq;\n"));
  CHECK(strstr(idl.s, "  viscera::EventKind kind;\n"));
  CHECK(strstr(idl.s, "  long task_id;\n  string<64> task_name;\n};\n};\n"));
  rt_str_free(&idl);
  rt_model_free(&m);
  /* a type name the information does not hold */
  CHECK(load(&m, &viscera_SessionEvent_desc, "viscera::Nope") < 0);
  rt_model_free(&m);
}

static void test_json(void) {
  viscera_SessionEvent e;
  memset(&e, 0, sizeof e);
  e.seq = 7;
  e.sim_time_ns = 1250000000ull;
  e.kind = viscera_EVENT_TASK_COMPLETED;
  e.organ_id = -1;
  e.tool_id = 1;
  e.value = 2.5;
  snprintf(e.text, sizeof e.text, "task 'remove-stone' completed \"ok\"");
  e.task_id = 1;
  snprintf(e.task_name, sizeof e.task_name, "remove-stone");
  rt_model_t m;
  CHECK(load(&m, &viscera_SessionEvent_desc, "viscera::SessionEvent") == 0);
  const char *want = "{\"source_id\":0,\"seq\":7,\"sim_time_ns\":1250000000,\"kind\":\"EVENT_TASK_COMPLETED\","
                     "\"organ_id\":-1,\"tool_id\":1,\"value\":2.5,\"text\":\"task 'remove-stone' completed "
                     "\\\"ok\\\"\",\"task_id\":1,\"task_name\":\"remove-stone\"}";
  for (int x = 1; x <= 2; x++) {
    size_t len;
    unsigned char *b = serialize(&e, &viscera_SessionEvent_desc, x, &len);
    rt_str_t o = {0};
    verr_t err = {{0}};
    CHECK(rt_cdr_json(m.top, b, len, &o, &err) == 0);
    CHECK(o.s && strcmp(o.s, want) == 0);
    if (o.s && strcmp(o.s, want) != 0) fprintf(stderr, "XCDR%d got %s\n", x, o.s);
    /* every truncation is refused and leaves the output as it was */
    int ok = 0;
    for (size_t n = 0; n < len; n++) {
      o.len = 0;
      ok += rt_cdr_json(m.top, b, n, &o, &err) == 0;
      CHECK(o.len == 0);
    }
    CHECK(ok == 0);
    /* a string length past the sample (the text's length field) */
    size_t text_len_at = len - 4 - 13 - 4 /* task_name */ - 4 /* task_id */ - (strlen(e.text) + 1);
    while (text_len_at % 4) text_len_at--; /* aligned: back to the length word */
    unsigned char save[4];
    memcpy(save, b + text_len_at, 4);
    memset(b + text_len_at, 0x7f, 4);
    CHECK(rt_cdr_json(m.top, b, len, &o, &err) < 0 && strstr(err.msg, "member 'text'"));
    memcpy(b + text_len_at, save, 4);
    rt_str_free(&o);
    free(b);
  }
  rt_model_free(&m);
}

static void test_csv(void) {
  viscera_ContactFeedback fb;
  memset(&fb, 0, sizeof fb);
  fb.tool_id = 2;
  fb.cmd_seq = 99;
  fb.sim_time_ns = 5000000;
  fb.in_contact = true;
  fb.organ_id = 0;
  fb.force[0] = 0.5f, fb.force[1] = -0.25f, fb.force[2] = 1.0f;
  fb.stiffness = 400;
  fb.seq = 7;
  rt_model_t m;
  CHECK(load(&m, &viscera_ContactFeedback_desc, "viscera::ContactFeedback") == 0);
  rt_str_t h = {0};
  rt_csv_header(m.top, &h);
  CHECK(h.s && strcmp(h.s, "tool_id,cmd_seq,cmd_client_mono_ns,sim_time_ns,in_contact,organ_id,proxy_position[0],"
                           "proxy_position[1],proxy_position[2],normal[0],normal[1],normal[2],stiffness,force[0],"
                           "force[1],force[2],seq") == 0);
  for (int x = 1; x <= 2; x++) {
    size_t len;
    unsigned char *b = serialize(&fb, &viscera_ContactFeedback_desc, x, &len);
    rt_str_t o = {0};
    verr_t err = {{0}};
    CHECK(rt_cdr_csv(m.top, b, len, &o, &err) == 0);
    CHECK(o.s && strcmp(o.s, "2,99,0,5000000,true,0,0,0,0,0,0,0,400,0.5,-0.25,1,7") == 0);
    /* a boolean that is neither 0 nor 1 */
    size_t at = x == 1 ? 4 + 32 : 4 + 28; /* XCDR2 aligns 8-byte fields to 4 */
    CHECK(b[at] == 1);
    b[at] = 5;
    CHECK(rt_cdr_csv(m.top, b, len, &o, &err) < 0 && strstr(err.msg, "boolean"));
    rt_str_free(&o);
    free(b);
  }
  /* not CDR at all */
  rt_str_t o = {0};
  verr_t err = {{0}};
  const unsigned char junk[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  CHECK(rt_cdr_csv(m.top, junk, sizeof junk, &o, &err) < 0);
  rt_str_free(&h);
  rt_model_free(&m);
}

static void test_sequences(void) {
  viscera_MeshDelta d;
  memset(&d, 0, sizeof d);
  uint32_t idx[2] = {3, 9};
  int16_t dq[6] = {1, -2, 3, -4, 5, -6};
  d.organ_id = 1;
  d.indices._length = d.indices._maximum = 2;
  d.indices._buffer = idx;
  d.dq._length = d.dq._maximum = 6;
  d.dq._buffer = dq;
  rt_model_t m;
  CHECK(load(&m, &viscera_MeshDelta_desc, "viscera::MeshDelta") == 0);
  size_t len;
  unsigned char *b = serialize(&d, &viscera_MeshDelta_desc, 1, &len);
  rt_str_t o = {0};
  verr_t err = {{0}};
  CHECK(rt_cdr_csv(m.top, b, len, &o, &err) == 0);
  CHECK(o.s && strcmp(o.s, "1,0,0,0,0,0,\"[3,9]\",\"[1,-2,3,-4,5,-6]\"") == 0);
  /* a sequence count far beyond the bytes left */
  size_t at = 4 + 4 * 4 + 8 + 4; /* organ_id..frame_seq, sim_time_ns, quant_step: the indices count */
  CHECK(b[at] == 2);
  b[at + 3] = 0x40;
  CHECK(rt_cdr_csv(m.top, b, len, &o, &err) < 0 && strstr(err.msg, "indices"));
  rt_str_free(&o);
  free(b);
  rt_model_free(&m);
}

typedef struct seen {
  int n;
  char kind[64], text[300];
  double tool_id, value, task_id;
} seen_t;

static void on_field(void *arg, const rt_field_t *f) {
  seen_t *s = arg;
  s->n++;
  if (!strcmp(f->path, "kind")) snprintf(s->kind, sizeof s->kind, "%s", f->str);
  if (!strcmp(f->path, "text")) snprintf(s->text, sizeof s->text, "%s", f->str);
  if (!strcmp(f->path, "tool_id")) s->tool_id = f->num;
  if (!strcmp(f->path, "value")) s->value = f->num;
  if (!strcmp(f->path, "task_id")) s->task_id = f->num;
}

/* Fields by name (how the report reads events of another type version). */
static void test_fields(void) {
  viscera_SessionEvent e;
  memset(&e, 0, sizeof e);
  e.kind = viscera_EVENT_THRESHOLD_CROSSED_UP;
  e.tool_id = -3;
  e.value = 0.8;
  e.task_id = -1;
  snprintf(e.text, sizeof e.text, "MPF crossed up: \"raw\" text");
  rt_model_t m;
  CHECK(load(&m, &viscera_SessionEvent_desc, "viscera::SessionEvent") == 0);
  size_t len;
  unsigned char *b = serialize(&e, &viscera_SessionEvent_desc, 1, &len);
  seen_t s = {0};
  verr_t err = {{0}};
  CHECK(rt_cdr_fields(m.top, b, len, on_field, &s, &err) == 0);
  CHECK(s.n == 10 && !strcmp(s.kind, "EVENT_THRESHOLD_CROSSED_UP") && !strcmp(s.text, e.text));
  CHECK(s.tool_id == -3 && s.value == 0.8 && s.task_id == -1);
  CHECK(rt_cdr_fields(m.top, b, len - 9, on_field, &s, &err) < 0);
  free(b);
  rt_model_free(&m);
}

int main(void) {
  test_fields();
  test_idl();
  test_json();
  test_csv();
  test_sequences();
  return check_report("test_rec_cdr");
}
