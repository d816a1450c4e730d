/* SPDX-License-Identifier: Apache-2.0 */
#include "events_by_name.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "recording/rec_cdr.h"
#include "recording/rec_types.h"
#include "recording/recording.h"
#include "viscera.h"

typedef struct salvage {
  rt_model_t model;
  rec_decode_cb cb;
  void *arg;
  uint64_t delivered, left;
  void *scratch; /* a compiled-type buffer for rec_decode_cdr */
} salvage_t;

static void on_field(void *arg, const rt_field_t *f) {
  viscera_SessionEvent *e = arg;
  const char *p = f->path;
  if (!strcmp(p, "source_id"))
    e->source_id = (uint32_t)f->num;
  else if (!strcmp(p, "seq"))
    e->seq = (uint64_t)f->num;
  else if (!strcmp(p, "sim_time_ns"))
    e->sim_time_ns = (uint64_t)strtoull(f->str, NULL, 10);
  else if (!strcmp(p, "organ_id"))
    e->organ_id = (int32_t)f->num;
  else if (!strcmp(p, "tool_id"))
    e->tool_id = (int32_t)f->num;
  else if (!strcmp(p, "value"))
    e->value = f->num;
  else if (!strcmp(p, "text"))
    snprintf(e->text, sizeof e->text, "%s", f->str);
  else if (!strcmp(p, "task_id"))
    e->task_id = (int32_t)f->num;
  else if (!strcmp(p, "task_name"))
    snprintf(e->task_name, sizeof e->task_name, "%.64s", f->str);
  else if (!strcmp(p, "kind")) {
    /* by literal: the recorded enum may number its kinds differently */
    int32_t k;
    e->kind = f->type->kind == RT_ENUM && rec_decode_enum_value(&viscera_SessionEvent_desc, f->str, &k)
                  ? (viscera_EventKind)k
                  : (viscera_EventKind)-1;
  }
}

static int on_row(void *arg, const recfile_row_t *row) {
  salvage_t *s = arg;
  if (row->kind != REC_KIND_DATA) return 0;
  if (rec_decode_cdr(row->cdr, row->cdr_len, &viscera_SessionEvent_desc, s->scratch)) {
    rec_decode_free(s->scratch, &viscera_SessionEvent_desc);
    return 0; /* the compiled type read it: delivered already */
  }
  viscera_SessionEvent e;
  memset(&e, 0, sizeof e);
  e.task_id = -1;
  e.kind = (viscera_EventKind)-1;
  verr_t err = {{0}};
  if (!s->model.top || rt_cdr_fields(s->model.top, row->cdr, row->cdr_len, on_field, &e, &err) < 0 ||
      (int32_t)e.kind < 0) {
    s->left++;
    return 0;
  }
  s->delivered++;
  return s->cb(s->arg, &e, row);
}

uint64_t rep_events_by_name(recfile_t *rf, rec_decode_cb cb, void *arg, uint64_t *left) {
  salvage_t s = {.cb = cb, .arg = arg};
  *left = 0;
  const recfile_topic_t *t = recfile_topic_by_name(rf, "viscera_SessionEvent");
  if (!t) return 0;
  verr_t err = {{0}};
  s.scratch = calloc(1, viscera_SessionEvent_desc.m_size);
  if (!s.scratch || rt_model_load_topic(&s.model, rf, t, &err) < 0) s.model.top = NULL;
  recfile_scan_report_t rep;
  if (s.scratch) recfile_scan(rf, t->id, true, on_row, &s, &rep);
  rt_model_free(&s.model);
  free(s.scratch);
  *left = s.left;
  return s.delivered;
}
