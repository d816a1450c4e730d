/* SPDX-License-Identifier: Apache-2.0 */
#include "recording/rec_types.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <dds/dds.h>
#include <dds/ddsi/ddsi_sertype.h>
#include <dds/ddsi/ddsi_typelib.h>
#include <dds/ddsi/ddsi_xt_impl.h>
#include <sqlite3.h>

typedef struct builder {
  rt_model_t *m;
  const ddsi_typemap_t *tm;
  const rt_type_t **done; /* per complete pair: its node once built */
  verr_t *err;
} builder_t;

static rt_type_t *new_node(builder_t *b, rt_kind_t kind) {
  rt_model_t *m = b->m;
  if (m->ntypes == m->cap) {
    size_t nc = m->cap ? 2 * m->cap : 32;
    rt_type_t **nt = realloc(m->types, nc * sizeof *nt);
    if (!nt) return NULL;
    m->types = nt, m->cap = nc;
  }
  rt_type_t *t = calloc(1, sizeof *t);
  if (!t) return NULL;
  t->kind = kind;
  m->types[m->ntypes++] = t;
  return t;
}

static char *dup_bounded(const char *s, size_t cap) {
  size_t len = strnlen(s, cap);
  char *d = malloc(len + 1);
  if (d) memcpy(d, s, len), d[len] = 0;
  return d;
}

static const rt_type_t *build(builder_t *b, const DDS_XTypes_TypeIdentifier *ti, int depth);

static int primitive_kind(uint8_t d) {
  switch (d) {
  case DDS_XTypes_TK_BOOLEAN:
    return RT_BOOL;
  case DDS_XTypes_TK_BYTE:
    return RT_OCTET;
  case DDS_XTypes_TK_CHAR8:
    return RT_CHAR;
#ifdef DDS_XTypes_TK_INT8 /* XTypes 1.3; Cyclone 0.10 has none */
  case DDS_XTypes_TK_INT8:
    return RT_INT8;
  case DDS_XTypes_TK_UINT8:
    return RT_UINT8;
#endif
  case DDS_XTypes_TK_INT16:
    return RT_INT16;
  case DDS_XTypes_TK_UINT16:
    return RT_UINT16;
  case DDS_XTypes_TK_INT32:
    return RT_INT32;
  case DDS_XTypes_TK_UINT32:
    return RT_UINT32;
  case DDS_XTypes_TK_INT64:
    return RT_INT64;
  case DDS_XTypes_TK_UINT64:
    return RT_UINT64;
  case DDS_XTypes_TK_FLOAT32:
    return RT_FLOAT32;
  case DDS_XTypes_TK_FLOAT64:
    return RT_FLOAT64;
  }
  return -1;
}

static const rt_type_t *build_struct(builder_t *b, const DDS_XTypes_CompleteStructType *st, int depth) {
  rt_type_t *t = new_node(b, RT_STRUCT);
  if (!t) return NULL;
  t->name = dup_bounded(st->header.detail.type_name, sizeof st->header.detail.type_name);
  t->ext = (st->struct_flags & DDS_XTypes_IS_MUTABLE)      ? RT_MUTABLE
           : (st->struct_flags & DDS_XTypes_IS_APPENDABLE) ? RT_APPENDABLE
                                                           : RT_FINAL;
  if (st->header.base_type._d != DDS_XTypes_TK_NONE) {
    t->base = build(b, &st->header.base_type, depth + 1);
    if (!t->base || t->base->kind != RT_STRUCT) return NULL;
  }
  uint32_t n = st->member_seq._length;
  t->members = calloc(n ? n : 1, sizeof *t->members);
  if (!t->members) return NULL;
  for (uint32_t i = 0; i < n; i++) {
    const DDS_XTypes_CompleteStructMember *sm = &st->member_seq._buffer[i];
    rt_member_t *mb = &t->members[i];
    mb->name = dup_bounded(sm->detail.name, sizeof sm->detail.name);
    mb->key = (sm->common.member_flags & DDS_XTypes_IS_KEY) != 0;
    mb->optional = (sm->common.member_flags & DDS_XTypes_IS_OPTIONAL) != 0;
    mb->id = sm->common.member_id;
    t->nmembers = i + 1;
    if (!mb->name || !(mb->type = build(b, &sm->common.member_type_id, depth + 1))) return NULL;
  }
  return t;
}

static const rt_type_t *build_enum(builder_t *b, const DDS_XTypes_CompleteEnumeratedType *en) {
  rt_type_t *t = new_node(b, RT_ENUM);
  if (!t) return NULL;
  t->name = dup_bounded(en->header.detail.type_name, sizeof en->header.detail.type_name);
  t->bit_bound = en->header.common.bit_bound;
  uint32_t n = en->literal_seq._length;
  t->literals = calloc(n ? n : 1, sizeof *t->literals);
  if (!t->literals || !t->name) return NULL;
  for (uint32_t i = 0; i < n; i++) {
    t->literals[i].value = en->literal_seq._buffer[i].common.value;
    t->literals[i].name =
        dup_bounded(en->literal_seq._buffer[i].detail.name, sizeof en->literal_seq._buffer[i].detail.name);
    t->nliterals = i + 1;
    if (!t->literals[i].name) return NULL;
  }
  return t;
}

static const rt_type_t *collection(builder_t *b, rt_kind_t kind, const DDS_XTypes_TypeIdentifier *elem, uint32_t bound,
                                   const uint32_t *dims, int ndims, int depth) {
  rt_type_t *t = new_node(b, kind);
  if (!t) return NULL;
  t->bound = bound;
  if (ndims > RT_MAX_DIMS) {
    verr_set(b->err, "array of %d dimensions (at most %d)", ndims, RT_MAX_DIMS);
    return NULL;
  }
  for (int i = 0; i < ndims; i++) t->dims[i] = dims[i];
  t->ndims = ndims;
  t->elem = build(b, elem, depth + 1);
  return t->elem ? t : NULL;
}

/* A hashed identifier: the complete type object it names. */
static const rt_type_t *build_hashed(builder_t *b, const DDS_XTypes_TypeIdentifier *ti, int depth) {
  const dds_sequence_DDS_XTypes_TypeIdentifierTypeObjectPair *pairs = &b->tm->x.identifier_object_pair_complete;
  for (uint32_t i = 0; i < pairs->_length; i++) {
    const DDS_XTypes_TypeIdentifier *k = &pairs->_buffer[i].type_identifier;
    if (k->_d != ti->_d || memcmp(k->_u.equivalence_hash, ti->_u.equivalence_hash, sizeof k->_u.equivalence_hash))
      continue;
    if (b->done[i]) return b->done[i];
    const DDS_XTypes_TypeObject *to = &pairs->_buffer[i].type_object;
    if (to->_d != DDS_XTypes_EK_COMPLETE) break;
    const DDS_XTypes_CompleteTypeObject *c = &to->_u.complete;
    const rt_type_t *t = NULL;
    switch (c->_d) {
    case DDS_XTypes_TK_STRUCTURE:
      t = build_struct(b, &c->_u.struct_type, depth);
      break;
    case DDS_XTypes_TK_ENUM:
      t = build_enum(b, &c->_u.enumerated_type);
      break;
    case DDS_XTypes_TK_ALIAS:
      t = build(b, &c->_u.alias_type.body.common.related_type, depth + 1);
      break;
    case DDS_XTypes_TK_SEQUENCE:
      t = collection(b, RT_SEQUENCE, &c->_u.sequence_type.element.common.type, c->_u.sequence_type.header.common.bound,
                     NULL, 0, depth);
      break;
    case DDS_XTypes_TK_ARRAY:
      t = collection(b, RT_ARRAY, &c->_u.array_type.element.common.type, 0,
                     c->_u.array_type.header.common.bound_seq._buffer,
                     (int)c->_u.array_type.header.common.bound_seq._length, depth);
      break;
    default:
      verr_set(b->err, "type kind %u is not supported", (unsigned)c->_d);
      return NULL;
    }
    b->done[i] = t;
    return t;
  }
  verr_set(b->err, "a type the type information refers to is missing from it");
  return NULL;
}

static const rt_type_t *build(builder_t *b, const DDS_XTypes_TypeIdentifier *ti, int depth) {
  if (depth > RT_MAX_DEPTH) {
    verr_set(b->err, "types nested deeper than %d", RT_MAX_DEPTH);
    return NULL;
  }
  int pk = primitive_kind(ti->_d);
  if (pk >= 0) return new_node(b, (rt_kind_t)pk);
  uint32_t dims[RT_MAX_DIMS];
  switch (ti->_d) {
  case DDS_XTypes_TI_STRING8_SMALL:
  case DDS_XTypes_TI_STRING8_LARGE: {
    rt_type_t *t = new_node(b, RT_STRING);
    if (t) t->bound = ti->_d == DDS_XTypes_TI_STRING8_SMALL ? ti->_u.string_sdefn.bound : ti->_u.string_ldefn.bound;
    return t;
  }
  case DDS_XTypes_TI_PLAIN_SEQUENCE_SMALL:
    return collection(b, RT_SEQUENCE, ti->_u.seq_sdefn.element_identifier, ti->_u.seq_sdefn.bound, NULL, 0, depth);
  case DDS_XTypes_TI_PLAIN_SEQUENCE_LARGE:
    return collection(b, RT_SEQUENCE, ti->_u.seq_ldefn.element_identifier, ti->_u.seq_ldefn.bound, NULL, 0, depth);
  case DDS_XTypes_TI_PLAIN_ARRAY_SMALL: {
    const DDS_XTypes_SBoundSeq *s = &ti->_u.array_sdefn.array_bound_seq;
    for (uint32_t i = 0; i < s->_length && i < RT_MAX_DIMS; i++) dims[i] = s->_buffer[i];
    return collection(b, RT_ARRAY, ti->_u.array_sdefn.element_identifier, 0, dims, (int)s->_length, depth);
  }
  case DDS_XTypes_TI_PLAIN_ARRAY_LARGE: {
    const DDS_XTypes_LBoundSeq *s = &ti->_u.array_ldefn.array_bound_seq;
    for (uint32_t i = 0; i < s->_length && i < RT_MAX_DIMS; i++) dims[i] = s->_buffer[i];
    return collection(b, RT_ARRAY, ti->_u.array_ldefn.element_identifier, 0, dims, (int)s->_length, depth);
  }
  case DDS_XTypes_EK_COMPLETE:
    return build_hashed(b, ti, depth);
  }
  verr_set(b->err, "type identifier kind %u is not supported", (unsigned)ti->_d);
  return NULL;
}

int rt_model_load(rt_model_t *m, const void *typemap, size_t len, const char *type_name, verr_t *err) {
  memset(m, 0, sizeof *m);
  if (!typemap || !len || len > UINT32_MAX) return verr_set(err, "type '%s': no type information stored", type_name);
  ddsi_sertype_cdr_data_t ser = {(uint32_t)len, (uint8_t *)typemap};
  ddsi_typemap_t *tm = ddsi_typemap_deser(&ser);
  if (!tm) return verr_set(err, "type '%s': the stored type information does not decode", type_name);
  const dds_sequence_DDS_XTypes_TypeIdentifierTypeObjectPair *pairs = &tm->x.identifier_object_pair_complete;
  builder_t b = {m, tm, calloc(pairs->_length ? pairs->_length : 1, sizeof *b.done), err};
  int ret = -1;
  if (!b.done) {
    verr_set(err, "out of memory");
  } else {
    for (uint32_t i = 0; i < pairs->_length && !m->top; i++) {
      const DDS_XTypes_TypeObject *to = &pairs->_buffer[i].type_object;
      if (to->_d == DDS_XTypes_EK_COMPLETE && to->_u.complete._d == DDS_XTypes_TK_STRUCTURE &&
          strcmp(to->_u.complete._u.struct_type.header.detail.type_name, type_name) == 0) {
        verr_t e = {{0}};
        b.err = &e;
        m->top = build(&b, &pairs->_buffer[i].type_identifier, 0);
        if (!m->top) verr_set(err, "type '%s': %s", type_name, e.msg[0] ? e.msg : "out of memory");
        break;
      }
    }
    if (m->top)
      ret = 0;
    else if (!err || !err->msg[0])
      verr_set(err, "type '%s' is not in its stored type information", type_name);
  }
  free(b.done);
  ddsi_typemap_fini(tm);
  dds_free(tm);
  return ret;
}

int rt_model_load_topic(rt_model_t *m, recfile_t *rf, const recfile_topic_t *t, verr_t *err) {
  memset(m, 0, sizeof *m);
  sqlite3 *db = recfile_sqlite(rf);
  sqlite3_stmt *st = NULL;
  if (sqlite3_prepare_v2(db, "SELECT typemap FROM topics WHERE id = ?", -1, &st, NULL) != SQLITE_OK) {
    sqlite3_finalize(st);
    return verr_set(err, "%s: topics table unreadable: %s", recfile_path(rf), sqlite3_errmsg(db));
  }
  sqlite3_bind_int64(st, 1, t->id);
  int ret;
  if (sqlite3_step(st) == SQLITE_ROW) {
    const void *blob = sqlite3_column_blob(st, 0);
    size_t len = blob ? (size_t)sqlite3_column_bytes(st, 0) : 0;
    ret = rt_model_load(m, blob, len, t->type_name, err);
  } else {
    ret = verr_set(err, "%s: topic %s: its row is unreadable", recfile_path(rf), t->name);
  }
  sqlite3_finalize(st);
  return ret;
}

void rt_model_free(rt_model_t *m) {
  for (size_t i = 0; i < m->ntypes; i++) {
    rt_type_t *t = m->types[i];
    free(t->name);
    for (uint32_t k = 0; k < t->nmembers; k++) free(t->members[k].name);
    free(t->members);
    for (uint32_t k = 0; k < t->nliterals; k++) free(t->literals[k].name);
    free(t->literals);
    free(t);
  }
  free(m->types);
  memset(m, 0, sizeof *m);
}

const char *rt_enum_name(const rt_type_t *e, int32_t value) {
  for (uint32_t i = 0; i < e->nliterals; i++)
    if (e->literals[i].value == value) return e->literals[i].name;
  return NULL;
}

void rt_str_append(rt_str_t *b, const char *s, size_t len) {
  if (b->oom) return;
  if (b->len + len + 1 > b->cap) {
    size_t nc = b->cap ? b->cap : 256;
    while (nc < b->len + len + 1) nc *= 2;
    char *ns = realloc(b->s, nc);
    if (!ns) {
      b->oom = true;
      return;
    }
    b->s = ns, b->cap = nc;
  }
  memcpy(b->s + b->len, s, len);
  b->len += len;
  b->s[b->len] = 0;
}

void rt_str_printf(rt_str_t *b, const char *fmt, ...) {
  char tmp[512];
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
  va_end(ap);
  if (n < 0) return;
  if ((size_t)n < sizeof tmp) {
    rt_str_append(b, tmp, (size_t)n);
    return;
  }
  char *big = malloc((size_t)n + 1);
  if (!big) {
    b->oom = true;
    return;
  }
  va_start(ap, fmt);
  vsnprintf(big, (size_t)n + 1, fmt, ap);
  va_end(ap);
  rt_str_append(b, big, (size_t)n);
  free(big);
}

void rt_str_free(rt_str_t *b) {
  free(b->s);
  memset(b, 0, sizeof *b);
}
