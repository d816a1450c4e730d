/* SPDX-License-Identifier: Apache-2.0 */
#include "recording/rec_idl.h"

#include <string.h>

static const char *primitive_idl(rt_kind_t k) {
  switch (k) {
  case RT_BOOL:
    return "boolean";
  case RT_OCTET:
    return "octet";
  case RT_CHAR:
    return "char";
  case RT_INT8:
    return "int8";
  case RT_UINT8:
    return "uint8";
  case RT_INT16:
    return "short";
  case RT_UINT16:
    return "unsigned short";
  case RT_INT32:
    return "long";
  case RT_UINT32:
    return "unsigned long";
  case RT_INT64:
    return "long long";
  case RT_UINT64:
    return "unsigned long long";
  case RT_FLOAT32:
    return "float";
  case RT_FLOAT64:
    return "double";
  default:
    return NULL;
  }
}

/* The type as it stands before a member name; arrays add their dimensions
 * after the name (member_dims). */
static int type_spec(const rt_type_t *t, rt_str_t *o, verr_t *err) {
  const char *p = primitive_idl(t->kind);
  if (p) {
    rt_str_printf(o, "%s", p);
    return 0;
  }
  switch (t->kind) {
  case RT_STRING:
    if (t->bound)
      rt_str_printf(o, "string<%u>", t->bound);
    else
      rt_str_printf(o, "string");
    return 0;
  case RT_ENUM:
  case RT_STRUCT:
    rt_str_printf(o, "%s", t->name);
    return 0;
  case RT_SEQUENCE:
    if (t->elem->kind == RT_ARRAY) return verr_set(err, "a sequence of arrays has no IDL spelling without a typedef");
    rt_str_printf(o, "sequence<");
    if (type_spec(t->elem, o, err) < 0) return -1;
    if (t->bound)
      rt_str_printf(o, ", %u>", t->bound);
    else
      rt_str_printf(o, ">");
    return 0;
  case RT_ARRAY:
    return type_spec(t->elem, o, err);
  default:
    return verr_set(err, "type kind %d has no IDL spelling", (int)t->kind);
  }
}

static void member_dims(const rt_type_t *t, rt_str_t *o) {
  for (; t->kind == RT_ARRAY; t = t->elem)
    for (int i = 0; i < t->ndims; i++) rt_str_printf(o, "[%u]", t->dims[i]);
}

/* "a::b::C": opens module a and b, returns the local name "C". */
static const char *open_modules(const char *qname, rt_str_t *o, int *nmod) {
  const char *p = qname, *sep;
  *nmod = 0;
  while ((sep = strstr(p, "::")) != NULL) {
    rt_str_printf(o, "module %.*s {\n", (int)(sep - p), p);
    (*nmod)++;
    p = sep + 2;
  }
  return p;
}

static void close_modules(int nmod, rt_str_t *o) {
  for (int i = 0; i < nmod; i++) rt_str_printf(o, "};\n");
}

typedef struct emit {
  const rt_type_t **done;
  size_t ndone, cap;
  rt_str_t *o;
  verr_t *err;
} emit_t;

static int emit_named(emit_t *e, const rt_type_t *t, int depth);

/* Emits the named types `t` uses (through collections) before it. */
static int emit_used(emit_t *e, const rt_type_t *t, int depth) {
  while (t->kind == RT_SEQUENCE || t->kind == RT_ARRAY) t = t->elem;
  if (t->kind == RT_STRUCT || t->kind == RT_ENUM) return emit_named(e, t, depth + 1);
  return 0;
}

static int emit_named(emit_t *e, const rt_type_t *t, int depth) {
  if (depth > RT_MAX_DEPTH) return verr_set(e->err, "types nested too deep");
  for (size_t i = 0; i < e->ndone; i++)
    if (e->done[i] == t || strcmp(e->done[i]->name, t->name) == 0) return 0;
  if (t->base && emit_named(e, t->base, depth + 1) < 0) return -1;
  for (uint32_t i = 0; i < t->nmembers; i++)
    if (emit_used(e, t->members[i].type, depth) < 0) return -1;
  if (e->ndone == e->cap) return verr_set(e->err, "more than %zu named types", e->cap);
  e->done[e->ndone++] = t;
  rt_str_t *o = e->o;
  int nmod;
  const char *local = open_modules(t->name, o, &nmod);
  if (t->kind == RT_ENUM) {
    rt_str_printf(o, "enum %s {\n", local);
    int32_t next = 0;
    for (uint32_t i = 0; i < t->nliterals; i++) {
      if (t->literals[i].value != next) rt_str_printf(o, "  @value(%d)\n", (int)t->literals[i].value);
      rt_str_printf(o, "  %s%s\n", t->literals[i].name, i + 1 < t->nliterals ? "," : "");
      next = t->literals[i].value + 1;
    }
    rt_str_printf(o, "};\n");
  } else {
    static const char *const EXT[] = {"@final", "@appendable", "@mutable"};
    rt_str_printf(o, "%s\nstruct %s", EXT[t->ext], local);
    if (t->base) rt_str_printf(o, " : %s", t->base->name);
    rt_str_printf(o, " {\n");
    for (uint32_t i = 0; i < t->nmembers; i++) {
      const rt_member_t *mb = &t->members[i];
      rt_str_printf(o, "  %s%s", mb->key ? "@key " : "", mb->optional ? "@optional " : "");
      if (type_spec(mb->type, o, e->err) < 0) return -1;
      rt_str_printf(o, " %s", mb->name);
      member_dims(mb->type, o);
      rt_str_printf(o, ";\n");
    }
    rt_str_printf(o, "};\n");
  }
  close_modules(nmod, o);
  return 0;
}

int rt_idl_text(const rt_model_t *m, rt_str_t *out, verr_t *err) {
  const rt_type_t *done[256];
  emit_t e = {done, 0, sizeof done / sizeof done[0], out, err};
  if (!m->top || m->top->kind != RT_STRUCT) return verr_set(err, "no struct type to describe");
  if (emit_named(&e, m->top, 0) < 0) return -1;
  if (out->oom) return verr_set(err, "out of memory");
  return 0;
}
