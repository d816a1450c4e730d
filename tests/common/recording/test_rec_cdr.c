/* SPDX-License-Identifier: Apache-2.0 */
/* rec_types, rec_idl, rec_cdr: a topic's type rebuilt from its XTypes
 * type information (here the compiled one, as the recorder stores it), its
 * OMG IDL text, and samples serialized as a writer does (XCDR2 of today's
 * @appendable types; XCDR1 as recordings of the final types hold it,
 * little-endian) decoded into JSON and CSV; every truncation and garbled
 * length is refused with a message, never read out of bounds. XCDR2
 * re-encoded as XCDR1 (the MCAP export) equals Cyclone's own XCDR1 of the
 * final type, byte for byte. */
#include <stdlib.h>
#include <string.h>

#include <dds/ddsi/ddsi_cdrstream.h>

#include "cdr_cases.h"
#include "check.h"
#include "recording/rec_cdr.h"
#include "recording/rec_idl.h"
#include "recording/rec_types.h"
#include "viscera.h"
#include "viscera_format2.h"

/* The final type of the same layout (format 2 froze these types unchanged
 * but final): Cyclone 0.10.2 writes XCDR1 only for final types, which is
 * what recordings made before the types became @appendable hold. */
static const dds_topic_descriptor_t *final_twin(const dds_topic_descriptor_t *desc) {
  if (desc == &viscera_SessionEvent_desc) return &viscera_format2_SessionEvent_desc;
  if (desc == &viscera_ContactFeedback_desc) return &viscera_format2_ContactFeedback_desc;
  if (desc == &viscera_MeshDelta_desc) return &viscera_format2_MeshDelta_desc;
  if (desc == &viscera_SceneInfo_desc) return &viscera_format2_SceneInfo_desc;
  if (desc == &viscera_AppliedInput_desc) return &viscera_format2_AppliedInput_desc;
  if (desc == &cdr_cases_Colors_desc) return &cdr_cases_ColorsFinal_desc;
  return NULL;
}

/* Encoding header + payload as stored; xcdr 1 (CDR_LE, with the final twin)
 * or 2 (D_CDR2_LE). Caller frees. */
static unsigned char *serialize(const void *sample, const dds_topic_descriptor_t *desc, int xcdr, size_t *len) {
  dds_ostream_t os;
  dds_ostream_init(&os, 0, (uint32_t)xcdr);
  dds_stream_write(&os, sample, (xcdr == 1 ? final_twin(desc) : desc)->m_ops);
  unsigned char *b = malloc(os.m_index + 4);
  b[0] = 0, b[1] = xcdr == 1 ? 1 : 9, b[2] = 0, b[3] = 0;
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
  CHECK(strstr(idl.s, "module viscera {\n@appendable\nstruct SceneInfo {\n  string<64> scene;\n"));
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
    size_t at = 4 + 32; /* XCDR1: 3 x 8 aligned to 8 after 4 + pad; XCDR2: DHEADER, then 8-byte fields aligned to 4 */
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

/* XCDR2 -> XCDR1 (rt_cdr_to_xcdr1) equals Cyclone's XCDR1 of the final
 * type, with nested appendable structs in a sequence (SceneInfo.tools,
 * AppliedInput.tools) and 8-byte members that XCDR1 aligns to 8; a member
 * an older writer lacks gets its default. */
static void check_x1(const void *sample, const dds_topic_descriptor_t *desc, const char *name) {
  rt_model_t m;
  CHECK(load(&m, desc, name) == 0);
  size_t l1, l2;
  unsigned char *b1 = serialize(sample, desc, 1, &l1), *b2 = serialize(sample, desc, 2, &l2);
  rt_str_t o = {0};
  verr_t err = {{0}};
  CHECK(rt_cdr_to_xcdr1(m.top, b2, l2, &o, &err) == 0);
  CHECK(o.len == l1 && memcmp(o.s, b1, l1) == 0);
  if (o.len != l1 || memcmp(o.s, b1, l1))
    fprintf(stderr, "%s: XCDR1 re-encoding differs (%zu vs %zu bytes)\n", name, o.len, l1);
  o.len = 0; /* XCDR1 in: copied */
  CHECK(rt_cdr_to_xcdr1(m.top, b1, l1, &o, &err) == 0 && o.len == l1 && memcmp(o.s, b1, l1) == 0);
  int ok = 0; /* every truncation refused, the output left as it was */
  for (size_t n = 0; n < l2; n++) {
    o.len = 0;
    ok += rt_cdr_to_xcdr1(m.top, b2, n, &o, &err) == 0;
    CHECK(o.len == 0);
  }
  CHECK(ok == 0);
  rt_str_free(&o);
  free(b1);
  free(b2);
  rt_model_free(&m);
}

/* Damaged XCDR2 samples (1-3 random bytes changed): never a crash or a
 * read out of bounds (this test runs under the sanitizers too), and every
 * re-encoding accepted is well-formed XCDR1 of the final type: Cyclone's
 * own reader (dds_stream_normalize) takes it. */
static void mutate_x1(const void *sample, const dds_topic_descriptor_t *desc, const char *name) {
  rt_model_t m;
  CHECK(load(&m, desc, name) == 0);
  size_t len;
  unsigned char *b = serialize(sample, desc, 2, &len), *g = malloc(len);
  rt_str_t o = {0};
  verr_t err = {{0}};
  int accepted = 0, refused = 0, wellformed = 0;
  srand(11);
  for (int k = 0; k < 4000; k++) {
    memcpy(g, b, len);
    for (int e = 1 + rand() % 3; e > 0; e--) g[4 + (size_t)rand() % (len - 4)] = (unsigned char)rand();
    o.len = 0;
    if (rt_cdr_to_xcdr1(m.top, g, len, &o, &err) < 0) {
      refused++;
      continue;
    }
    accepted++;
    uint32_t off = 0, size = (uint32_t)(o.len - 4);
    char *p = malloc(size ? size : 1);
    memcpy(p, o.s + 4, size);
    wellformed += dds_stream_normalize_data(p, &off, size, false, 1, final_twin(desc)->m_ops) != NULL;
    free(p);
  }
  printf("%s: 4000 damaged XCDR2 samples: %d re-encoded (%d taken by Cyclone's XCDR1 reader), %d refused\n", name,
         accepted, wellformed, refused);
  CHECK(wellformed == accepted && refused > 0 && accepted > 0);
  rt_str_free(&o);
  free(g);
  free(b);
  rt_model_free(&m);
}

static void test_xcdr1(void) {
  viscera_SceneInfo si;
  memset(&si, 0, sizeof si);
  snprintf(si.scene, sizeof si.scene, "kidney");
  si.physics_dt = 0.001, si.publish_hz = 60, si.quant_step = 1e-5f;
  viscera_ToolInfo tools[2];
  memset(tools, 0, sizeof tools);
  tools[0].tool_id = 0, tools[0].mpf = 0.8f;
  snprintf(tools[0].name, sizeof tools[0].name, "probe");
  tools[1].tool_id = 1, tools[1].radius = 0.002f;
  snprintf(tools[1].kind, sizeof tools[1].kind, "grasper");
  si.tools._buffer = tools;
  si.tools._length = si.tools._maximum = 2;
  check_x1(&si, &viscera_SceneInfo_desc, "viscera::SceneInfo");
  mutate_x1(&si, &viscera_SceneInfo_desc, "viscera::SceneInfo");
  viscera_AppliedInput in;
  memset(&in, 0, sizeof in);
  in.tick = 5, in.step = 4, in.sim_time_ns = 4000000, in.seq = 3;
  viscera_AppliedTool at = {.tool_id = 0,
                            .position = {0.01, -0.02, 0.03},
                            .orientation = {1, 0, 0, 0},
                            .buttons = 1,
                            .max_force = 3,
                            .cmd_seq = 9};
  viscera_AppliedControl ac = {.source_id = 7,
                               .seq = 1,
                               .kind = viscera_CONTROL_GUIDE,
                               .tool_id = 0,
                               .organ_id = -1,
                               .values = {0.5, 200, 0, 0},
                               .result = 0,
                               .task = -1};
  snprintf(ac.text, sizeof ac.text, "instructor1");
  in.tools._buffer = &at, in.tools._length = in.tools._maximum = 1;
  in.controls._buffer = &ac, in.controls._length = in.controls._maximum = 1;
  check_x1(&in, &viscera_AppliedInput_desc, "viscera::AppliedInput");
  mutate_x1(&in, &viscera_AppliedInput_desc, "viscera::AppliedInput");
  /* An older writer's SessionEvent (no task_id, task_name: its DHEADER ends
   * before them): they get their defaults, -> the XCDR1 of the event with
   * task_id 0 and task_name "". */
  viscera_SessionEvent e;
  memset(&e, 0, sizeof e);
  e.seq = 3, e.kind = viscera_EVENT_CUT_END, e.value = 1.5;
  snprintf(e.text, sizeof e.text, "cut");
  size_t l1, l2;
  unsigned char *b1 = serialize(&e, &viscera_SessionEvent_desc, 1, &l1);
  unsigned char *b2 = serialize(&e, &viscera_SessionEvent_desc, 2, &l2);
  /* the old sample: DHEADER shortened by task_id (4) and task_name ("" = 4 + 1 bytes, after padding) */
  size_t old_len = l2 - 9;
  while ((old_len - 4) % 4) old_len--; /* the text's end, aligned as the DHEADER counts it */
  uint32_t dh = (uint32_t)(old_len - 8);
  memcpy(b2 + 4, &dh, 4);
  rt_model_t m;
  CHECK(load(&m, &viscera_SessionEvent_desc, "viscera::SessionEvent") == 0);
  rt_str_t o = {0};
  verr_t err = {{0}};
  CHECK(rt_cdr_to_xcdr1(m.top, b2, old_len, &o, &err) == 0);
  CHECK(o.len == l1 && memcmp(o.s, b1, l1) == 0);
  b2[1] = 11; /* PL_CDR2_LE: mutable, refused */
  CHECK(rt_cdr_to_xcdr1(m.top, b2, l2, &o, &err) < 0);
  rt_str_free(&o);
  rt_model_free(&m);
  free(b1);
  free(b2);
}

/* Collections of enums and of strings carry a DHEADER in XCDR2, of octets
 * none: JSON and CSV (the enum array split into columns) from both
 * encodings, and the XCDR1 re-encoding. */
static void test_collections(void) {
  cdr_cases_Color seq[3] = {cdr_cases_GREEN, cdr_cases_BLUE, cdr_cases_RED};
  char names[2][9] = {"ab", "cdef"};
  uint8_t raw[3] = {1, 2, 255};
  cdr_cases_Colors v = {.seq = {3, 3, seq, false},
                        .names = {2, 2, names, false},
                        .arr = {cdr_cases_BLUE, cdr_cases_GREEN},
                        .raw = {3, 3, raw, false},
                        .last = -0.5};
  rt_model_t m;
  CHECK(load(&m, &cdr_cases_Colors_desc, "cdr_cases::Colors") == 0);
  const char *want = "{\"seq\":[\"GREEN\",\"BLUE\",\"RED\"],\"names\":[\"ab\",\"cdef\"],\"arr\":[\"BLUE\",\"GREEN\"],"
                     "\"raw\":[1,2,255],\"last\":-0.5}";
  const char *want_csv =
      "\"[\"\"GREEN\"\",\"\"BLUE\"\",\"\"RED\"\"]\",\"[\"\"ab\"\",\"\"cdef\"\"]\",\"BLUE\",\"GREEN\","
      "\"[1,2,255]\",-0.5";
  for (int x = 1; x <= 2; x++) {
    size_t len;
    unsigned char *b = serialize(&v, &cdr_cases_Colors_desc, x, &len);
    rt_str_t o = {0};
    verr_t err = {{0}};
    CHECK(rt_cdr_json(m.top, b, len, &o, &err) == 0 && o.s && strcmp(o.s, want) == 0);
    if (!o.s || strcmp(o.s, want)) fprintf(stderr, "XCDR%d: %s %s\n", x, o.s ? o.s : "", err.msg);
    rt_str_free(&o);
    CHECK(rt_cdr_csv(m.top, b, len, &o, &err) == 0 && o.s && strcmp(o.s, want_csv) == 0);
    if (!o.s || strcmp(o.s, want_csv)) fprintf(stderr, "CSV XCDR%d: %s %s\n", x, o.s ? o.s : "", err.msg);
    rt_str_free(&o);
    free(b);
  }
  rt_model_free(&m);
  check_x1(&v, &cdr_cases_Colors_desc, "cdr_cases::Colors");
}

int main(void) {
  test_collections();
  test_xcdr1();
  test_fields();
  test_idl();
  test_json();
  test_csv();
  test_sequences();
  return check_report("test_rec_cdr");
}
