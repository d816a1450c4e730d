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

static bool is_scalar(const rt_type_t *t) { return t->kind <= RT_ENUM; }
/* XTypes' primitive types: not strings, not enums. XCDR2 puts a DHEADER
 * before a sequence or array of anything else, enums included (Cyclone
 * 0.10.2 does: docs/dds.md "Schema evolution"). */
static bool is_primitive(const rt_type_t *t) { return t->kind < RT_STRING; }

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
static int scalar(cur_t *c, const rt_type_t *t, rt_str_t *o, int mode) {
  bool csv = mode != AS_JSON;
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
  } v;
  switch (t->kind) {
  case RT_BOOL:
    if (rd(c, &v.u8, 1) < 0) return -1;
    if (v.u8 > 1) return fail(c, "boolean neither 0 nor 1");
    rt_str_printf(o, "%s", mode == AS_RAW ? (v.u8 ? "1" : "0") : v.u8 ? "true" : "false");
    return 0;
  case RT_OCTET:
  case RT_UINT8:
    return rd(c, &v.u8, 1) < 0 ? -1 : (rt_str_printf(o, "%u", v.u8), 0);
  case RT_INT8:
    return rd(c, &v.i8, 1) < 0 ? -1 : (rt_str_printf(o, "%d", v.i8), 0);
  case RT_CHAR: {
    if (rd(c, &v.u8, 1) < 0) return -1;
    char ch = (char)v.u8;
    if (mode == AS_RAW)
      rt_str_append(o, &ch, 1);
    else if (csv)
      rt_str_printf(o, "\"%s%c\"", ch == '"' ? "\"" : "", ch);
    else
      json_string(o, &ch, 1);
    return 0;
  }
  case RT_INT16:
    return rd(c, &v.i16, 2) < 0 ? -1 : (rt_str_printf(o, "%d", v.i16), 0);
  case RT_UINT16:
    return rd(c, &v.u16, 2) < 0 ? -1 : (rt_str_printf(o, "%u", v.u16), 0);
  case RT_INT32:
    return rd(c, &v.i32, 4) < 0 ? -1 : (rt_str_printf(o, "%d", (int)v.i32), 0);
  case RT_UINT32:
    return rd(c, &v.u32, 4) < 0 ? -1 : (rt_str_printf(o, "%u", (unsigned)v.u32), 0);
  case RT_INT64:
    return rd(c, &v.i64, 8) < 0 ? -1 : (rt_str_printf(o, "%lld", (long long)v.i64), 0);
  case RT_UINT64:
    return rd(c, &v.u64, 8) < 0 ? -1 : (rt_str_printf(o, "%llu", (unsigned long long)v.u64), 0);
  case RT_FLOAT32:
  case RT_FLOAT64: {
    double d;
    if (t->kind == RT_FLOAT32) {
      if (rd(c, &v.f, 4) < 0) return -1;
      d = v.f;
    } else {
      if (rd(c, &v.d, 8) < 0) return -1;
      d = v.d;
    }
    if (!isfinite(d))
      rt_str_printf(o, "%s", csv ? (isnan(d) ? "nan" : d > 0 ? "inf" : "-inf") : "null");
    else
      rt_str_printf(o, t->kind == RT_FLOAT32 ? "%.9g" : "%.17g", d);
    return 0;
  }
  case RT_ENUM: {
    int32_t e = 0;
    int bits = t->bit_bound ? t->bit_bound : 32;
    if (!c->v2 || bits > 16) {
      if (rd(c, &v.i32, 4) < 0) return -1;
      e = v.i32;
    } else if (bits > 8) {
      if (rd(c, &v.i16, 2) < 0) return -1;
      e = v.i16;
    } else {
      if (rd(c, &v.i8, 1) < 0) return -1;
      e = v.i8;
    }
    const char *name = rt_enum_name(t, e);
    if (name)
      rt_str_printf(o, mode == AS_RAW ? "%s" : "\"%s\"", name);
    else
      rt_str_printf(o, "%d", (int)e);
    return 0;
  }
  case RT_STRING: {
    uint32_t len;
    if (rd_u32(c, &len) < 0) return -1;
    if (len == 0 || len > c->n - c->pos) return fail(c, "string length out of range");
    if (t->bound && len - 1 > t->bound) return fail(c, "string longer than its bound");
    const char *s = (const char *)c->b + c->pos;
    if (s[len - 1] != 0 || memchr(s, 0, len - 1)) return fail(c, "string not NUL-terminated");
    c->pos += len;
    if (mode == AS_RAW) {
      rt_str_append(o, s, len - 1);
      return 0;
    }
    if (!csv) {
      json_string(o, s, len - 1);
      return 0;
    }
    rt_str_append(o, "\"", 1);
    for (uint32_t i = 0; i + 1 < len; i++) {
      if (s[i] == '"') rt_str_append(o, "\"", 1);
      rt_str_append(o, s[i] == '\n' || s[i] == '\r' ? " " : &s[i], 1);
    }
    rt_str_append(o, "\"", 1);
    return 0;
  }
  default:
    return fail(c, "not a scalar");
  }
}

static int json_value(cur_t *c, const rt_type_t *t, rt_str_t *o, int depth);

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

static int json_struct(cur_t *c, const rt_type_t *t, rt_str_t *o, int depth, bool *first) {
  if (t->ext == RT_MUTABLE) return fail(c, "mutable struct");
  size_t end;
  if (dheader(c, t->ext == RT_APPENDABLE, &end) < 0) return -1;
  if (t->base && json_struct(c, t->base, o, depth + 1, first) < 0) return -1;
  for (uint32_t i = 0; i < t->nmembers; i++) {
    const rt_member_t *m = &t->members[i];
    if (m->optional) return fail(c, "optional members are not decoded");
    rt_str_printf(o, "%s", *first ? "" : ",");
    *first = false;
    json_string(o, m->name, strlen(m->name));
    rt_str_append(o, ":", 1);
    c->where = m->name;
    if (end != SIZE_MAX && c->pos >= end)
      rt_str_printf(o, "null"); /* written by an older type */
    else if (json_value(c, m->type, o, depth + 1) < 0)
      return -1;
  }
  if (end != SIZE_MAX) c->pos = end; /* skip members a newer type appended */
  return 0;
}

static int json_elements(cur_t *c, const rt_type_t *elem, uint64_t n, rt_str_t *o, int depth) {
  /* every element takes at least one byte: a count beyond the bytes left is garbage */
  if (n > c->n - c->pos) return fail(c, "element count beyond the sample");
  rt_str_append(o, "[", 1);
  for (uint64_t i = 0; i < n; i++) {
    if (i) rt_str_append(o, ",", 1);
    if (json_value(c, elem, o, depth + 1) < 0) return -1;
  }
  rt_str_append(o, "]", 1);
  return 0;
}

static int json_value(cur_t *c, const rt_type_t *t, rt_str_t *o, int depth) {
  if (depth > RT_MAX_DEPTH * 2) return fail(c, "nested too deep");
  if (is_scalar(t)) return scalar(c, t, o, AS_JSON);
  size_t end;
  switch (t->kind) {
  case RT_STRUCT: {
    bool first = true;
    rt_str_append(o, "{", 1);
    if (json_struct(c, t, o, depth, &first) < 0) return -1;
    rt_str_append(o, "}", 1);
    return 0;
  }
  case RT_SEQUENCE: {
    if (dheader(c, !is_primitive(t->elem), &end) < 0) return -1;
    uint32_t n;
    if (rd_u32(c, &n) < 0) return -1;
    if (t->bound && n > t->bound) return fail(c, "sequence longer than its bound");
    if (json_elements(c, t->elem, n, o, depth) < 0) return -1;
    if (end != SIZE_MAX) c->pos = end;
    return 0;
  }
  case RT_ARRAY: {
    if (dheader(c, !is_primitive(t->elem), &end) < 0) return -1;
    uint64_t n = 1;
    for (int i = 0; i < t->ndims; i++) n *= t->dims[i];
    if (json_elements(c, t->elem, n, o, depth) < 0) return -1;
    if (end != SIZE_MAX) c->pos = end;
    return 0;
  }
  default:
    return fail(c, "unknown type kind");
  }
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
      for (uint32_t k = 0; k < mt->dims[0]; k++) {
        rt_str_printf(o, "%s", *first ? "" : ",");
        *first = false;
        if (scalar(c, mt->elem, o, AS_CSV) < 0) return -1;
      }
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

/* XCDR1 re-encoding (rt_cdr_to_xcdr1). XCDR1 aligns every primitive to its
 * size (at most 8) from the start of the payload, has no DHEADER, and
 * encodes an enum in 4 bytes; values keep the sample's byte order. */
typedef struct x1 {
  rt_str_t *o;
  size_t base; /* where the payload starts in o */
  size_t cap;  /* most payload bytes written: defaults of absent members must not blow up */
} x1_t;

static int x1_put(cur_t *c, x1_t *x, const void *host, size_t size) {
  static const char zero[8] = {0};
  size_t rel = x->o->len - x->base, pad = (size - rel % size) % size;
  if (rel + pad + size > x->cap) return fail(c, "re-encoded sample too large");
  uint8_t tmp[8];
  memcpy(tmp, host, size);
  if (c->swap)
    for (size_t i = 0; i < size / 2; i++) {
      uint8_t t = tmp[i];
      tmp[i] = tmp[size - 1 - i], tmp[size - 1 - i] = t;
    }
  rt_str_append(x->o, zero, pad);
  rt_str_append(x->o, (const char *)tmp, size);
  return x->o->oom ? verr_set(c->err, "out of memory") : 0;
}

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

/* The default value (XTypes: zero, "", empty, an enum's first literal) of
 * a member an older writer's sample lacks. */
static int x1_default(cur_t *c, const rt_type_t *t, x1_t *x, int depth) {
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
    if (t->base && x1_default(c, t->base, x, depth + 1) < 0) return -1;
    for (uint32_t i = 0; i < t->nmembers; i++)
      if (x1_default(c, t->members[i].type, x, depth + 1) < 0) return -1;
    return 0;
  case RT_SEQUENCE:
    return x1_put(c, x, zero, 4);
  case RT_ARRAY: {
    uint64_t n = 1;
    for (int i = 0; i < t->ndims; i++) n *= t->dims[i];
    for (uint64_t i = 0; i < n; i++)
      if (x1_default(c, t->elem, x, depth + 1) < 0) return -1;
    return 0;
  }
  default:
    return x1_put(c, x, zero, prim_size(t));
  }
}

static int x1_value(cur_t *c, const rt_type_t *t, x1_t *x, int depth);

static int x1_elements(cur_t *c, const rt_type_t *elem, uint64_t n, x1_t *x, int depth) {
  if (n > c->n - c->pos) return fail(c, "element count beyond the sample");
  for (uint64_t i = 0; i < n; i++)
    if (x1_value(c, elem, x, depth + 1) < 0) return -1;
  return 0;
}

static int x1_value(cur_t *c, const rt_type_t *t, x1_t *x, int depth) {
  if (depth > RT_MAX_DEPTH * 2) return fail(c, "nested too deep");
  size_t end;
  switch (t->kind) {
  case RT_STRUCT: {
    if (t->ext == RT_MUTABLE) return fail(c, "mutable struct");
    if (dheader(c, t->ext == RT_APPENDABLE, &end) < 0) return -1;
    if (t->base && x1_value(c, t->base, x, depth + 1) < 0) return -1;
    for (uint32_t i = 0; i < t->nmembers; i++) {
      const rt_member_t *m = &t->members[i];
      c->where = m->name;
      if (m->optional) return fail(c, "optional members are not decoded");
      int r = end != SIZE_MAX && c->pos >= end ? x1_default(c, m->type, x, depth + 1) /* an older writer's */
                                               : x1_value(c, m->type, x, depth + 1);
      if (r < 0) return -1;
    }
    if (end != SIZE_MAX) {
      if (c->pos > end) return fail(c, "members run past their struct's DHEADER");
      c->pos = end; /* members a newer type appended are dropped */
    }
    return 0;
  }
  case RT_SEQUENCE: {
    if (dheader(c, !is_primitive(t->elem), &end) < 0) return -1;
    uint32_t n;
    if (rd_u32(c, &n) < 0 || x1_put(c, x, &n, 4) < 0) return -1;
    if (t->bound && n > t->bound) return fail(c, "sequence longer than its bound");
    if (x1_elements(c, t->elem, n, x, depth) < 0) return -1;
    if (end != SIZE_MAX) c->pos = end;
    return 0;
  }
  case RT_ARRAY: {
    if (dheader(c, !is_primitive(t->elem), &end) < 0) return -1;
    uint64_t n = 1;
    for (int i = 0; i < t->ndims; i++) n *= t->dims[i];
    if (x1_elements(c, t->elem, n, x, depth) < 0) return -1;
    if (end != SIZE_MAX) c->pos = end;
    return 0;
  }
  case RT_STRING: {
    uint32_t len;
    if (rd_u32(c, &len) < 0) return -1;
    if (len == 0 || len > c->n - c->pos) return fail(c, "string length out of range");
    if (t->bound && len - 1 > t->bound) return fail(c, "string longer than its bound");
    const char *s = (const char *)c->b + c->pos;
    if (s[len - 1] != 0 || memchr(s, 0, len - 1)) return fail(c, "string not NUL-terminated");
    if (x1_put(c, x, &len, 4) < 0) return -1;
    if (x->o->len - x->base + len > x->cap) return fail(c, "re-encoded sample too large");
    rt_str_append(x->o, s, len);
    c->pos += len;
    return 0;
  }
  case RT_ENUM: {
    int32_t e = 0;
    int bits = t->bit_bound ? t->bit_bound : 32;
    if (!c->v2 || bits > 16) {
      if (rd(c, &e, 4) < 0) return -1;
    } else if (bits > 8) {
      int16_t v;
      if (rd(c, &v, 2) < 0) return -1;
      e = v;
    } else {
      int8_t v;
      if (rd(c, &v, 1) < 0) return -1;
      e = v;
    }
    if (!rt_enum_name(t, e)) return fail(c, "enum value the type does not have");
    return x1_put(c, x, &e, 4);
  }
  case RT_BOOL: {
    uint8_t v;
    if (rd(c, &v, 1) < 0) return -1;
    if (v > 1) return fail(c, "boolean neither 0 nor 1");
    return x1_put(c, x, &v, 1);
  }
  default: {
    if (!is_scalar(t)) return fail(c, "unknown type kind");
    uint8_t v[8];
    size_t size = prim_size(t);
    if (rd(c, v, size) < 0) return -1;
    return x1_put(c, x, v, size);
  }
  }
}

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
  if (x1_value(&c, top, &x, 0) < 0 || out->oom) {
    if (out->oom) verr_set(err, "out of memory");
    out->len = mark;
    if (out->s) out->s[mark] = 0;
    return -1;
  }
  return 0;
}
