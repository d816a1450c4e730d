/* SPDX-License-Identifier: Apache-2.0 */
#include "recording/rec_cdr.h"

#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

typedef struct cur {
  const uint8_t *b; /* payload, after the 4-byte encoding header */
  size_t n, pos;
  bool swap, v2;
  verr_t *err;
  const char *where; /* member being read, for messages */
} cur_t;

static int fail(cur_t *c, const char *what) {
  return verr_set(c->err, "%s at member '%s' (byte %zu of %zu)", what, c->where ? c->where : "?", c->pos + 4, c->n + 4);
}

static int rd(cur_t *c, void *out, size_t size) {
  size_t a = c->v2 && size > 4 ? 4 : size; /* XCDR2 aligns to at most 4 */
  size_t pos = (c->pos + a - 1) / a * a;
  if (pos > c->n || c->n - pos < size) return fail(c, "sample ends early");
  uint8_t tmp[8];
  memcpy(tmp, c->b + pos, size);
  if (c->swap)
    for (size_t i = 0; i < size / 2; i++) {
      uint8_t x = tmp[i];
      tmp[i] = tmp[size - 1 - i], tmp[size - 1 - i] = x;
    }
  memcpy(out, tmp, size);
  c->pos = pos + size;
  return 0;
}

static int rd_u32(cur_t *c, uint32_t *v) { return rd(c, v, 4); }

static int begin(cur_t *c, const void *cdr, size_t len, verr_t *err) {
  const uint8_t *b = cdr;
  memset(c, 0, sizeof *c);
  c->err = err;
  if (!b || len < 4 || b[0] != 0) return verr_set(err, "not a CDR sample (encoding header)");
  unsigned id = b[1];
  if (id == 2 || id == 3 || id == 10 || id == 11)
    return verr_set(err, "parameter-list (mutable) samples are not decoded");
  if (id > 9 || id == 4 || id == 5) return verr_set(err, "unknown CDR encoding %u", id);
  c->b = b + 4;
  c->n = len - 4;
  c->v2 = id >= 6;
  bool le = (id & 1u) != 0;
  uint16_t one = 1;
  bool host_le = *(const uint8_t *)&one == 1;
  c->swap = le != host_le;
  return 0;
}

/* XCDR2: appendable structs and collections of non-primitives start with
 * their size; *end is where they stop (SIZE_MAX when there is no header). */
static int dheader(cur_t *c, bool has, size_t *end) {
  *end = SIZE_MAX;
  if (!c->v2 || !has) return 0;
  uint32_t size;
  if (rd_u32(c, &size) < 0) return -1;
  if (size > c->n - c->pos) return fail(c, "DHEADER beyond the sample");
  *end = c->pos + size;
  return 0;
}

static bool is_scalar(const rt_type_t *t) { return t->kind <= RT_ENUM; }
/* XTypes' primitive types: not strings, not enums. XCDR2 puts a DHEADER
 * before a sequence or array of anything else, enums included (Cyclone
 * 0.10.2 does: docs/dds.md "Schema evolution"). */
static bool is_primitive(const rt_type_t *t) { return t->kind < RT_STRING; }

/* Bytes of a primitive (XCDR1's size and alignment; an enum as XCDR1 and
 * XCDR2 with no bit bound encode it). */
static size_t prim_size(const rt_type_t *t) {
  switch (t->kind) {
  case RT_INT16:
  case RT_UINT16:
    return 2;
  case RT_INT32:
  case RT_UINT32:
  case RT_FLOAT32:
  case RT_ENUM:
    return 4;
  case RT_INT64:
  case RT_UINT64:
  case RT_FLOAT64:
    return 8;
  default:
    return 1;
  }
}

/* One scalar as read from the sample, in host byte order. */
typedef struct sval {
  union {
    uint8_t u8;
    int8_t i8;
    uint16_t u16;
    int16_t i16;
    uint32_t u32;
    int32_t i32;
    uint64_t u64;
    int64_t i64;
    float f;
    double d;
  } v;           /* primitives (booleans checked 0 or 1); enums in i32 */
  const char *s; /* a string: its bytes in the sample, NUL-terminated, */
  uint32_t slen; /* that NUL included */
} sval_t;

/* Reads and checks one scalar. A string's bytes are not stepped over: its
 * reader does that once the visitor has seen them (so an error the visitor
 * raises names the string's start, as the length before it). */
static int read_scalar(cur_t *c, const rt_type_t *t, sval_t *v) {
  switch (t->kind) {
  case RT_ENUM: {
    int bits = t->bit_bound ? t->bit_bound : 32;
    if (!c->v2 || bits > 16) return rd(c, &v->v.i32, 4);
    if (bits > 8) {
      if (rd(c, &v->v.i16, 2) < 0) return -1;
      v->v.i32 = v->v.i16;
    } else {
      if (rd(c, &v->v.i8, 1) < 0) return -1;
      v->v.i32 = v->v.i8;
    }
    return 0;
  }
  case RT_STRING: {
    uint32_t len;
    if (rd_u32(c, &len) < 0) return -1;
    if (len == 0 || len > c->n - c->pos) return fail(c, "string length out of range");
    if (t->bound && len - 1 > t->bound) return fail(c, "string longer than its bound");
    const char *s = (const char *)c->b + c->pos;
    if (s[len - 1] != 0 || memchr(s, 0, len - 1)) return fail(c, "string not NUL-terminated");
    v->s = s;
    v->slen = len;
    return 0;
  }
  case RT_BOOL:
    if (rd(c, &v->v.u8, 1) < 0) return -1;
    return v->v.u8 > 1 ? fail(c, "boolean neither 0 nor 1") : 0;
  default:
    return rd(c, &v->v, prim_size(t));
  }
}

static void json_string(rt_str_t *o, const char *s, size_t len) {
  rt_str_append(o, "\"", 1);
  for (size_t i = 0; i < len; i++) {
    unsigned char ch = (unsigned char)s[i];
    if (ch == '"' || ch == '\\')
      rt_str_printf(o, "\\%c", ch);
    else if (ch < 0x20 || ch == 0x7f)
      rt_str_printf(o, "\\u%04x", ch);
    else
      rt_str_append(o, (const char *)&s[i], 1);
  }
  rt_str_append(o, "\"", 1);
}

enum { AS_JSON, AS_CSV, AS_RAW };

/* A scalar as text: JSON (strings quoted, non-finite null), CSV (strings
 * quoted with "" doubling, non-finite as nan/inf) or raw (strings and enum
 * literals as they are, booleans 1/0, for rt_cdr_fields). */
static void scalar_text(const rt_type_t *t, const sval_t *v, rt_str_t *o, int mode) {
  bool csv = mode != AS_JSON;
  switch (t->kind) {
  case RT_BOOL:
    rt_str_printf(o, "%s", mode == AS_RAW ? (v->v.u8 ? "1" : "0") : v->v.u8 ? "true" : "false");
    return;
  case RT_OCTET:
  case RT_UINT8:
    rt_str_printf(o, "%u", v->v.u8);
    return;
  case RT_INT8:
    rt_str_printf(o, "%d", v->v.i8);
    return;
  case RT_CHAR: {
    char ch = (char)v->v.u8;
    if (mode == AS_RAW)
      rt_str_append(o, &ch, 1);
    else if (csv)
      rt_str_printf(o, "\"%s%c\"", ch == '"' ? "\"" : "", ch);
    else
      json_string(o, &ch, 1);
    return;
  }
  case RT_INT16:
    rt_str_printf(o, "%d", v->v.i16);
    return;
  case RT_UINT16:
    rt_str_printf(o, "%u", v->v.u16);
    return;
  case RT_INT32:
    rt_str_printf(o, "%d", (int)v->v.i32);
    return;
  case RT_UINT32:
    rt_str_printf(o, "%u", (unsigned)v->v.u32);
    return;
  case RT_INT64:
    rt_str_printf(o, "%lld", (long long)v->v.i64);
    return;
  case RT_UINT64:
    rt_str_printf(o, "%llu", (unsigned long long)v->v.u64);
    return;
  case RT_FLOAT32:
  case RT_FLOAT64: {
    double d = t->kind == RT_FLOAT32 ? v->v.f : v->v.d;
    if (!isfinite(d))
      rt_str_printf(o, "%s", csv ? (isnan(d) ? "nan" : d > 0 ? "inf" : "-inf") : "null");
    else
      rt_str_printf(o, t->kind == RT_FLOAT32 ? "%.9g" : "%.17g", d);
    return;
  }
  case RT_ENUM: {
    const char *name = rt_enum_name(t, v->v.i32);
    if (name)
      rt_str_printf(o, mode == AS_RAW ? "%s" : "\"%s\"", name);
    else
      rt_str_printf(o, "%d", (int)v->v.i32);
    return;
  }
  default: { /* RT_STRING */
    if (mode == AS_RAW) {
      rt_str_append(o, v->s, v->slen - 1);
    } else if (!csv) {
      json_string(o, v->s, v->slen - 1);
    } else {
      rt_str_append(o, "\"", 1);
      for (uint32_t i = 0; i + 1 < v->slen; i++) {
        if (v->s[i] == '"') rt_str_append(o, "\"", 1);
        rt_str_append(o, v->s[i] == '\n' || v->s[i] == '\r' ? " " : &v->s[i], 1);
      }
      rt_str_append(o, "\"", 1);
    }
  }
  }
}

/* One scalar read, checked and appended as text to `o`. */
static int scalar(cur_t *c, const rt_type_t *t, rt_str_t *o, int mode) {
  sval_t v = {.slen = 0};
  if (read_scalar(c, t, &v) < 0) return -1;
  scalar_text(t, &v, o, mode);
  c->pos += v.slen; /* a string's bytes (0 for anything else) */
  return 0;
}

/* The walk over a sample along its type that the JSON decoding and the
 * XCDR1 re-encoding share (CSV and rt_cdr_fields take their collections
 * through the JSON visitor): it reads and checks everything (DHEADERs,
 * lengths against the bytes left and the type's bounds, booleans, strings,
 * the nesting depth) and tells the visitor what it met, in sample order.
 * A visitor's callback returns 0, or -1 with the error set (fail). NULL
 * callbacks are skipped, except scalar and absent. */
typedef struct walk_ops {
  int (*scalar)(void *ctx, cur_t *c, const rt_type_t *t, const sval_t *v);
  void (*struct_open)(void *ctx);
  void (*struct_close)(void *ctx);
  /* before member m's value (or absent), nth counting from 0 over the
   * struct's members, its bases' first */
  void (*member)(void *ctx, const rt_member_t *m, uint32_t nth);
  /* a member an appendable sample written with an older type lacks */
  int (*absent)(void *ctx, cur_t *c, const rt_type_t *t, int depth);
  /* a sequence (its length just read, before it is checked) or an array */
  int (*coll_open)(void *ctx, cur_t *c, const rt_type_t *t, uint64_t n);
  void (*elem)(void *ctx, uint64_t i); /* before element i */
  void (*coll_close)(void *ctx);
  /* members that run past their struct's DHEADER are an error, as for
   * Cyclone's reader (the re-encoding); the text decoders go on at the
   * DHEADER's end */
  bool exact_dheader;
} walk_ops_t;

typedef struct walk {
  cur_t *c;
  const walk_ops_t *ops;
  void *ctx;
} walk_t;

static int walk_value(const walk_t *w, const rt_type_t *t, int depth);

static int walk_members(const walk_t *w, const rt_type_t *t, int depth, uint32_t *nth) {
  cur_t *c = w->c;
  if (depth > RT_MAX_DEPTH * 2) return fail(c, "nested too deep");
  if (t->ext == RT_MUTABLE) return fail(c, "mutable struct");
  size_t end;
  if (dheader(c, t->ext == RT_APPENDABLE, &end) < 0) return -1;
  if (t->base && walk_members(w, t->base, depth + 1, nth) < 0) return -1;
  for (uint32_t i = 0; i < t->nmembers; i++) {
    const rt_member_t *m = &t->members[i];
    c->where = m->name;
    if (m->optional) return fail(c, "optional members are not decoded");
    if (w->ops->member) w->ops->member(w->ctx, m, (*nth)++);
    int r = end != SIZE_MAX && c->pos >= end ? w->ops->absent(w->ctx, c, m->type, depth + 1) /* an older writer's */
                                             : walk_value(w, m->type, depth + 1);
    if (r < 0) return -1;
  }
  if (end != SIZE_MAX) {
    if (w->ops->exact_dheader && c->pos > end) return fail(c, "members run past their struct's DHEADER");
    c->pos = end; /* skip members a newer type appended */
  }
  return 0;
}

static int walk_value(const walk_t *w, const rt_type_t *t, int depth) {
  cur_t *c = w->c;
  const walk_ops_t *ops = w->ops;
  if (depth > RT_MAX_DEPTH * 2) return fail(c, "nested too deep");
  if (is_scalar(t)) {
    sval_t v = {.slen = 0};
    if (read_scalar(c, t, &v) < 0 || ops->scalar(w->ctx, c, t, &v) < 0) return -1;
    c->pos += v.slen; /* a string's bytes */
    return 0;
  }
  switch (t->kind) {
  case RT_STRUCT: {
    uint32_t nth = 0;
    if (ops->struct_open) ops->struct_open(w->ctx);
    if (walk_members(w, t, depth, &nth) < 0) return -1;
    if (ops->struct_close) ops->struct_close(w->ctx);
    return 0;
  }
  case RT_SEQUENCE:
  case RT_ARRAY: {
    size_t end;
    if (dheader(c, !is_primitive(t->elem), &end) < 0) return -1;
    uint64_t n = 1;
    if (t->kind == RT_SEQUENCE) {
      uint32_t len;
      if (rd_u32(c, &len) < 0) return -1;
      n = len;
    } else {
      for (int i = 0; i < t->ndims; i++) n *= t->dims[i];
    }
    if (ops->coll_open && ops->coll_open(w->ctx, c, t, n) < 0) return -1;
    if (t->kind == RT_SEQUENCE && t->bound && n > t->bound) return fail(c, "sequence longer than its bound");
    /* every element takes at least one byte: a count beyond the bytes left is garbage */
    if (n > c->n - c->pos) return fail(c, "element count beyond the sample");
    for (uint64_t i = 0; i < n; i++) {
      if (ops->elem) ops->elem(w->ctx, i);
      if (walk_value(w, t->elem, depth + 1) < 0) return -1;
    }
    if (ops->coll_close) ops->coll_close(w->ctx);
    if (end != SIZE_MAX) c->pos = end;
    return 0;
  }
  default:
    return fail(c, "unknown type kind");
  }
}

/* JSON (rt_cdr_json): the walk's visitor writing text into an rt_str_t. */
static int json_scalar(void *o, cur_t *c, const rt_type_t *t, const sval_t *v) {
  (void)c;
  scalar_text(t, v, o, AS_JSON);
  return 0;
}
static void json_open(void *o) { rt_str_append(o, "{", 1); }
static void json_close(void *o) { rt_str_append(o, "}", 1); }
static void json_member(void *o, const rt_member_t *m, uint32_t nth) {
  if (nth) rt_str_append(o, ",", 1);
  json_string(o, m->name, strlen(m->name));
  rt_str_append(o, ":", 1);
}
static int json_absent(void *o, cur_t *c, const rt_type_t *t, int depth) {
  (void)c, (void)t, (void)depth;
  rt_str_append(o, "null", 4); /* written by an older type */
  return 0;
}
static int json_coll_open(void *o, cur_t *c, const rt_type_t *t, uint64_t n) {
  (void)c, (void)t, (void)n;
  rt_str_append(o, "[", 1);
  return 0;
}
static void json_elem(void *o, uint64_t i) {
  if (i) rt_str_append(o, ",", 1);
}
static void json_coll_close(void *o) { rt_str_append(o, "]", 1); }

static const walk_ops_t json_ops = {json_scalar,    json_open, json_close,      json_member, json_absent,
                                    json_coll_open, json_elem, json_coll_close, false};

static int json_value(cur_t *c, const rt_type_t *t, rt_str_t *o, int depth) {
  walk_t w = {c, &json_ops, o};
  return walk_value(&w, t, depth);
}

int rt_cdr_json(const rt_type_t *top, const void *cdr, size_t len, rt_str_t *out, verr_t *err) {
  cur_t c;
  if (begin(&c, cdr, len, err) < 0) return -1;
  size_t mark = out->len;
  if (json_value(&c, top, out, 0) < 0) {
    out->len = mark;
    if (out->s) out->s[mark] = 0;
    return -1;
  }
  return out->oom ? verr_set(err, "out of memory") : 0;
}

/* CSV: what becomes columns of its own. */
static bool split_array(const rt_type_t *t) {
  if (t->kind != RT_ARRAY || !is_scalar(t->elem) || t->ndims != 1) return false;
  return t->dims[0] <= RT_CSV_MAX_SPLIT;
}

static void header_of(const rt_type_t *t, const char *prefix, rt_str_t *o, bool *first) {
  if (t->base) header_of(t->base, prefix, o, first);
  for (uint32_t i = 0; i < t->nmembers; i++) {
    const rt_member_t *m = &t->members[i];
    char name[512];
    snprintf(name, sizeof name, "%s%s%s", prefix, prefix[0] ? "." : "", m->name);
    if (m->type->kind == RT_STRUCT) {
      header_of(m->type, name, o, first);
    } else if (split_array(m->type)) {
      for (uint32_t k = 0; k < m->type->dims[0]; k++) {
        rt_str_printf(o, "%s%s[%u]", *first ? "" : ",", name, k);
        *first = false;
      }
    } else {
      rt_str_printf(o, "%s%s", *first ? "" : ",", name);
      *first = false;
    }
  }
}

void rt_csv_header(const rt_type_t *top, rt_str_t *out) {
  bool first = true;
  header_of(top, "", out, &first);
}

static void csv_empty_cells(const rt_type_t *t, rt_str_t *o, bool *first) {
  rt_str_t h = {0};
  bool f = true;
  if (t->kind == RT_STRUCT) {
    header_of(t, "x", &h, &f);
  } else {
    rt_str_printf(&h, "x");
  }
  size_t cells = 1;
  for (size_t i = 0; i < h.len; i++) cells += h.s[i] == ',';
  if (split_array(t)) cells = t->dims[0];
  for (size_t i = 0; i < cells; i++) {
    rt_str_printf(o, "%s", *first ? "" : ",");
    *first = false;
  }
  rt_str_free(&h);
}

static int csv_struct(cur_t *c, const rt_type_t *t, rt_str_t *o, bool *first) {
  if (t->ext == RT_MUTABLE) return fail(c, "mutable struct");
  size_t end;
  if (dheader(c, t->ext == RT_APPENDABLE, &end) < 0) return -1;
  if (t->base && csv_struct(c, t->base, o, first) < 0) return -1;
  for (uint32_t i = 0; i < t->nmembers; i++) {
    const rt_member_t *m = &t->members[i];
    const rt_type_t *mt = m->type;
    c->where = m->name;
    if (m->optional) return fail(c, "optional members are not decoded");
    if (end != SIZE_MAX && c->pos >= end) {
      csv_empty_cells(mt, o, first);
      continue;
    }
    if (mt->kind == RT_STRUCT) {
      if (csv_struct(c, mt, o, first) < 0) return -1;
    } else if (split_array(mt)) {
      size_t aend; /* XCDR2: an array of enums or strings starts with a DHEADER */
      if (dheader(c, !is_primitive(mt->elem), &aend) < 0) return -1;
      for (uint32_t k = 0; k < mt->dims[0]; k++) {
        rt_str_printf(o, "%s", *first ? "" : ",");
        *first = false;
        if (scalar(c, mt->elem, o, AS_CSV) < 0) return -1;
      }
      if (aend != SIZE_MAX) c->pos = aend;
    } else if (is_scalar(mt)) {
      rt_str_printf(o, "%s", *first ? "" : ",");
      *first = false;
      if (scalar(c, mt, o, AS_CSV) < 0) return -1;
    } else {
      rt_str_t j = {0};
      int r = json_value(c, mt, &j, 1);
      rt_str_printf(o, "%s\"", *first ? "" : ",");
      *first = false;
      for (size_t k = 0; r == 0 && k < j.len; k++)
        rt_str_append(o, j.s[k] == '"' ? "\"\"" : &j.s[k], j.s[k] == '"' ? 2 : 1);
      rt_str_append(o, "\"", 1);
      rt_str_free(&j);
      if (r < 0) return -1;
    }
  }
  if (end != SIZE_MAX) c->pos = end;
  return 0;
}

int rt_cdr_csv(const rt_type_t *top, const void *cdr, size_t len, rt_str_t *out, verr_t *err) {
  cur_t c;
  if (begin(&c, cdr, len, err) < 0) return -1;
  if (top->kind != RT_STRUCT) return verr_set(err, "the topic type is not a struct");
  size_t mark = out->len;
  bool first = true;
  if (csv_struct(&c, top, out, &first) < 0) {
    out->len = mark;
    if (out->s) out->s[mark] = 0;
    return -1;
  }
  return out->oom ? verr_set(err, "out of memory") : 0;
}

typedef struct visit {
  rt_field_cb cb;
  void *arg;
  rt_str_t tmp;
} visit_t;

static int visit_struct(cur_t *c, const rt_type_t *t, const char *prefix, visit_t *v, int depth) {
  if (t->ext == RT_MUTABLE) return fail(c, "mutable struct");
  if (depth > RT_MAX_DEPTH) return fail(c, "nested too deep");
  size_t end;
  if (dheader(c, t->ext == RT_APPENDABLE, &end) < 0) return -1;
  if (t->base && visit_struct(c, t->base, prefix, v, depth + 1) < 0) return -1;
  for (uint32_t i = 0; i < t->nmembers && (end == SIZE_MAX || c->pos < end); i++) {
    const rt_member_t *m = &t->members[i];
    char path[512];
    snprintf(path, sizeof path, "%s%s%s", prefix, prefix[0] ? "." : "", m->name);
    c->where = m->name;
    if (m->optional) return fail(c, "optional members are not decoded");
    v->tmp.len = 0;
    if (v->tmp.s) v->tmp.s[0] = 0;
    if (m->type->kind == RT_STRUCT) {
      if (visit_struct(c, m->type, path, v, depth + 1) < 0) return -1;
    } else if (is_scalar(m->type)) {
      if (scalar(c, m->type, &v->tmp, AS_RAW) < 0) return -1;
      if (v->tmp.oom) return verr_set(c->err, "out of memory");
      rt_field_t f = {path, m->type, strtod(v->tmp.s, NULL), v->tmp.s};
      if (m->type->kind == RT_ENUM)
        for (uint32_t k = 0; k < m->type->nliterals; k++)
          if (strcmp(m->type->literals[k].name, v->tmp.s) == 0) f.num = m->type->literals[k].value;
      v->cb(v->arg, &f);
    } else if (json_value(c, m->type, &v->tmp, depth + 1) < 0) { /* collections: skipped over */
      return -1;
    }
  }
  if (end != SIZE_MAX) c->pos = end;
  return 0;
}

int rt_cdr_fields(const rt_type_t *top, const void *cdr, size_t len, rt_field_cb cb, void *arg, verr_t *err) {
  cur_t c;
  if (begin(&c, cdr, len, err) < 0) return -1;
  if (top->kind != RT_STRUCT) return verr_set(err, "the topic type is not a struct");
  visit_t v = {cb, arg, {0}};
  int r = visit_struct(&c, top, "", &v, 0);
  rt_str_free(&v.tmp);
  return r;
}

/* XCDR1 re-encoding (rt_cdr_to_xcdr1): the walk's visitor writing XCDR1.
 * XCDR1 aligns every primitive to its size (at most 8) from the start of
 * the payload, has no DHEADER, and encodes an enum in 4 bytes; values keep
 * the sample's byte order. */
typedef struct x1 {
  rt_str_t *o;
  size_t base; /* where the payload starts in o */
  size_t cap;  /* most payload bytes written: defaults of absent members must not blow up */
} x1_t;

static int x1_put(cur_t *c, x1_t *x, const void *host, size_t size) {
  size_t rel = x->o->len - x->base, pad = (size - rel % size) % size;
  if (rel + pad + size > x->cap) return fail(c, "re-encoded sample too large");
  uint8_t tmp[16] = {0}; /* the padding (zeros), then the value in the sample's byte order: one append */
  memcpy(tmp + pad, host, size);
  if (c->swap)
    for (size_t i = 0; i < size / 2; i++) {
      uint8_t t = tmp[pad + i];
      tmp[pad + i] = tmp[pad + size - 1 - i], tmp[pad + size - 1 - i] = t;
    }
  rt_str_append(x->o, (const char *)tmp, pad + size);
  return x->o->oom ? verr_set(c->err, "out of memory") : 0;
}

/* The default value (XTypes: zero, "", empty, an enum's first literal) of
 * a member an older writer's sample lacks. */
static int x1_default(void *ctx, cur_t *c, const rt_type_t *t, int depth) {
  x1_t *x = ctx;
  if (depth > RT_MAX_DEPTH * 2) return fail(c, "nested too deep");
  uint8_t zero[8] = {0};
  switch (t->kind) {
  case RT_ENUM: {
    int32_t v = t->nliterals ? t->literals[0].value : 0;
    return x1_put(c, x, &v, 4);
  }
  case RT_STRING: {
    uint32_t one = 1;
    if (x1_put(c, x, &one, 4) < 0) return -1;
    return x1_put(c, x, zero, 1);
  }
  case RT_STRUCT:
    if (t->base && x1_default(x, c, t->base, depth + 1) < 0) return -1;
    for (uint32_t i = 0; i < t->nmembers; i++)
      if (x1_default(x, c, t->members[i].type, depth + 1) < 0) return -1;
    return 0;
  case RT_SEQUENCE:
    return x1_put(c, x, zero, 4);
  case RT_ARRAY: {
    uint64_t n = 1;
    for (int i = 0; i < t->ndims; i++) n *= t->dims[i];
    for (uint64_t i = 0; i < n; i++)
      if (x1_default(x, c, t->elem, depth + 1) < 0) return -1;
    return 0;
  }
  default:
    return x1_put(c, x, zero, prim_size(t));
  }
}

static int x1_scalar(void *ctx, cur_t *c, const rt_type_t *t, const sval_t *v) {
  x1_t *x = ctx;
  switch (t->kind) {
  case RT_STRING:
    if (x1_put(c, x, &v->slen, 4) < 0) return -1;
    if (x->o->len - x->base + v->slen > x->cap) return fail(c, "re-encoded sample too large");
    rt_str_append(x->o, v->s, v->slen);
    return 0;
  case RT_ENUM:
    if (!rt_enum_name(t, v->v.i32)) return fail(c, "enum value the type does not have");
    return x1_put(c, x, &v->v.i32, 4);
  default:
    return x1_put(c, x, &v->v, prim_size(t));
  }
}

static int x1_coll_open(void *ctx, cur_t *c, const rt_type_t *t, uint64_t n) {
  uint32_t len = (uint32_t)n;
  return t->kind == RT_SEQUENCE ? x1_put(c, ctx, &len, 4) : 0; /* an array's length is its type's */
}

static const walk_ops_t x1_ops = {x1_scalar, NULL, NULL, NULL, x1_default, x1_coll_open, NULL, NULL, true};

int rt_cdr_to_xcdr1(const rt_type_t *top, const void *cdr, size_t len, rt_str_t *out, verr_t *err) {
  cur_t c;
  if (begin(&c, cdr, len, err) < 0) return -1;
  size_t mark = out->len;
  const uint8_t *b = cdr;
  if (!c.v2) { /* already XCDR1 */
    rt_str_append(out, cdr, len);
    return out->oom ? verr_set(err, "out of memory") : 0;
  }
  const char head[4] = {0, (char)(b[1] & 1u), 0, 0}; /* CDR_BE 0 / CDR_LE 1: the sample's byte order */
  rt_str_append(out, head, 4);
  x1_t x = {out, out->len, len * 64 + 65536};
  walk_t w = {&c, &x1_ops, &x};
  if (walk_value(&w, top, 0) < 0 || out->oom) {
    if (out->oom) verr_set(err, "out of memory");
    out->len = mark;
    if (out->s) out->s[mark] = 0;
    return -1;
  }
  return 0;
}
