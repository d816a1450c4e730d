/* SPDX-License-Identifier: Apache-2.0 */
#include "recording/rec_decode.h"

#include <stdlib.h>
#include <string.h>

#include <dds/ddsi/ddsi_cdrstream.h>
#include <dds/ddsi/ddsi_sertype.h>
#include <dds/ddsi/ddsi_typelib.h>
#include <dds/ddsi/ddsi_xt_impl.h>

#include "recording/recording.h"
#include "viscera_format1.h"
#include "viscera_format2.h"

/* The frozen twins of a compiled-in type (idl/viscera_formatN.idl), newest
 * format first, by the type's name after its module; NULL past the last.
 * Only a twin whose C struct fits in the compiled one is taken (it reads
 * into its prefix). */
#define FORMAT_TWINS(m)                                                                                                \
  {                                                                                                                    \
    &m##_SceneInfo_desc, &m##_MeshState_desc, &m##_MeshDelta_desc, &m##_ToolCommand_desc, &m##_ContactFeedback_desc,   \
        &m##_SessionEvent_desc, &m##_Metrics_desc, &m##_SessionControl_desc, &m##_ToolRole_desc,                       \
        &m##_ObjectState_desc, &m##_ToolMetrics_desc, &m##_AppliedInput_desc, &m##_SceneSource_desc                    \
  }
enum { NFORMATS = 2, NTWINS = 13 };
static const dds_topic_descriptor_t *format_twin(const dds_topic_descriptor_t *desc, int newest_first) {
  static const dds_topic_descriptor_t *const twins[NFORMATS][NTWINS] = {FORMAT_TWINS(viscera_format2),
                                                                        FORMAT_TWINS(viscera_format1)};
  if (newest_first < 0 || newest_first >= NFORMATS) return NULL;
  const char *name = desc->m_typename ? strrchr(desc->m_typename, ':') : NULL;
  if (!name) return NULL;
  const dds_topic_descriptor_t *const *list = twins[newest_first];
  for (size_t i = 0; i < NTWINS; i++) {
    const char *t = strrchr(list[i]->m_typename, ':');
    if (list[i] != desc && !strcmp(t, name) && list[i]->m_size <= desc->m_size) return list[i];
  }
  return NULL;
}

/* Normalizes a copy of the payload against `ops` and reads it into out. */
static bool decode_with(const unsigned char *payload, uint32_t size, bool bswap, uint32_t xcdrv, const uint32_t *ops,
                        void *out) {
  /* normalize works in place (byte swap), so on a copy: the caller's bytes
   * may be SQLite's own buffer. */
  char *buf = malloc(size ? size : 1);
  if (!buf) return false;
  memcpy(buf, payload, size);
  uint32_t off = 0;
  bool ok = dds_stream_normalize_data(buf, &off, size, bswap, xcdrv, ops) != NULL;
  if (ok) {
    dds_istream_t is;
    dds_istream_init(&is, size, buf, xcdrv);
    dds_stream_read(&is, out, ops);
    dds_istream_fini(&is);
  }
  free(buf);
  return ok;
}

/* rec_decode_cdr with the ops to read by (NULL: desc's own; a format-1
 * twin's read into the prefix of desc's struct). */
static bool decode_cdr_ops(const void *cdr, size_t len, const dds_topic_descriptor_t *desc, const uint32_t *ops,
                           void *out) {
  memset(out, 0, desc->m_size); /* dds_stream_read would free or reuse garbage pointers */
  const unsigned char *b = cdr;
  if (!b || len < 4 || len - 4 > UINT32_MAX || b[0] != 0) return false;
  unsigned id = b[1];
  /* Encoding identifiers 0..3 are (PL_)CDR1, 6..11 XCDR2; others unknown. */
  if (id > 11 || id == 4 || id == 5) return false;
  /* All zero bytes is what a zero-filled page of a damaged or truncated
   * file holds; it would pass as a big-endian sample of zeros (a tool at
   * the origin), so it is refused. A real writer never produces it: the
   * encoding header alone is non-zero on little-endian hosts, and a
   * big-endian sample of only zeros carries no information. */
  size_t nz = 0;
  while (nz < len && b[nz] == 0) nz++;
  if (nz == len) return false;
  bool le = (id & 1u) != 0;
  uint32_t xcdrv = id <= 3 ? 1 : 2;
  uint32_t size = (uint32_t)(len - 4);
  bool bswap = le != (DDSRT_ENDIAN == DDSRT_LITTLE_ENDIAN);
  return decode_with(b + 4, size, bswap, xcdrv, ops ? ops : desc->m_ops, out);
}

bool rec_decode_cdr(const void *cdr, size_t len, const dds_topic_descriptor_t *desc, void *out) {
  return decode_cdr_ops(cdr, len, desc, NULL, out);
}

void rec_decode_free(void *sample, const dds_topic_descriptor_t *desc) {
  dds_stream_free_sample(sample, desc->m_ops);
  memset(sample, 0, desc->m_size);
}

bool rec_decode_enum_value(const dds_topic_descriptor_t *desc, const char *literal, int32_t *value) {
  if (!desc->type_mapping.data || !desc->type_mapping.sz) return false;
  ddsi_sertype_cdr_data_t ser = {desc->type_mapping.sz, (uint8_t *)desc->type_mapping.data};
  ddsi_typemap_t *tm = ddsi_typemap_deser(&ser);
  if (!tm) return false;
  bool found = false;
  const dds_sequence_DDS_XTypes_TypeIdentifierTypeObjectPair *pairs = &tm->x.identifier_object_pair_complete;
  for (uint32_t i = 0; i < pairs->_length && !found; i++) {
    const DDS_XTypes_TypeObject *to = &pairs->_buffer[i].type_object;
    if (to->_d != DDS_XTypes_EK_COMPLETE || to->_u.complete._d != DDS_XTypes_TK_ENUM) continue;
    const DDS_XTypes_CompleteEnumeratedLiteralSeq *lits = &to->_u.complete._u.enumerated_type.literal_seq;
    for (uint32_t k = 0; k < lits->_length; k++)
      if (strcmp(lits->_buffer[k].detail.name, literal) == 0) {
        *value = lits->_buffer[k].common.value;
        found = true;
        break;
      }
  }
  ddsi_typemap_fini(tm);
  dds_free(tm); /* fini frees the contents, not the struct */
  return found;
}

typedef struct decode_ctx {
  const dds_topic_descriptor_t *desc;
  const uint32_t *ops; /* NULL, or the format-1 twin's (the topic was recorded with it) */
  void *sample;
  rec_decode_cb cb;
  void *arg;
  rec_decode_report_t *rep;
} decode_ctx_t;

static int on_row(void *arg, const recfile_row_t *row) {
  decode_ctx_t *c = arg;
  if (row->kind != REC_KIND_DATA) return 0;
  if (!decode_cdr_ops(row->cdr, row->cdr_len, c->desc, c->ops, c->sample)) {
    if (c->rep->undecodable++ == 0) c->rep->first_undecodable = row->id;
    return 0;
  }
  c->rep->decoded++;
  int stop = c->cb(c->arg, c->sample, row);
  rec_decode_free(c->sample, c->desc);
  return stop;
}

/* Stops a scan at the first data row that decodes with ctx->ops (NULL:
 * the descriptor's own). */
typedef struct probe_ctx {
  const dds_topic_descriptor_t *desc;
  const uint32_t *ops;
  void *sample;
  bool found;
} probe_ctx_t;
static int probe_row(void *arg, const recfile_row_t *row) {
  probe_ctx_t *p = arg;
  if (row->kind != REC_KIND_DATA || !decode_cdr_ops(row->cdr, row->cdr_len, p->desc, p->ops, p->sample)) return 0;
  rec_decode_free(p->sample, p->desc);
  p->found = true;
  return 1;
}

/* A topic recorded before its type grew (fields appended at its end) holds
 * samples of an older format that the grown type does not read: when not
 * one data row decodes with the compiled type, the frozen twins
 * (idl/viscera_formatN.idl) are tried newest first, and the whole topic is
 * read with the first one that decodes a row, into the prefix of the
 * compiled struct (the appended fields stay zero). Newest first because an
 * XCDR1 sample with more fields than a twin still decodes with it (the
 * trailing bytes are ignored) and would lose what it appended. Decided per
 * topic, never per sample, so a truncated sample of the compiled type is
 * not taken for an older one. Returns the twin's ops or NULL. */
static const uint32_t *older_format_ops(recfile_t *rf, int64_t topic_id, const dds_topic_descriptor_t *desc,
                                        void *sample) {
  probe_ctx_t p = {desc, NULL, sample, false};
  recfile_scan_report_t r;
  recfile_scan(rf, topic_id, true, probe_row, &p, &r);
  if (p.found || r.rows == 0) return NULL;
  for (int f = 0; f < NFORMATS; f++) {
    const dds_topic_descriptor_t *twin = format_twin(desc, f);
    /* the compiled type itself may be the newest format: skip identical ops */
    if (!twin || twin->m_ops == desc->m_ops) continue;
    p.ops = twin->m_ops;
    recfile_scan(rf, topic_id, true, probe_row, &p, &r);
    if (p.found) return twin->m_ops;
  }
  return NULL;
}

int rec_decode_topic(recfile_t *rf, const char *topic, const dds_topic_descriptor_t *desc, rec_decode_cb cb, void *arg,
                     rec_decode_report_t *rep) {
  memset(rep, 0, sizeof *rep);
  const recfile_topic_t *t = recfile_topic_by_name(rf, topic);
  if (!t) {
    rep->topic_missing = true;
    return 0;
  }
  decode_ctx_t c = {desc, NULL, calloc(1, desc->m_size ? desc->m_size : 1), cb, arg, rep};
  if (!c.sample) return -1;
  c.ops = older_format_ops(rf, t->id, desc, c.sample);
  recfile_scan(rf, t->id, true, on_row, &c, &rep->scan);
  free(c.sample);
  return 0;
}
