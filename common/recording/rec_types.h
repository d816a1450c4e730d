/* SPDX-License-Identifier: Apache-2.0 */
/* rec_types: the type of a recorded topic as a small tree, rebuilt from
 * the XTypes type information the recording stores beside its samples (the
 * topics.typemap column, recording.h): structs with their member names and
 * key flags, enums with their literals, strings, sequences and arrays with
 * their bounds. Readers that must not depend on this build's compiled
 * types use it: the IDL text of a topic (rec_idl.h) and the decoding of
 * stored CDR into named values (rec_cdr.h) for the exports of
 * viscera-recinfo.
 *
 * Nothing stored is trusted: unknown kinds, dangling type references and
 * nesting deeper than RT_MAX_DEPTH are refused with a message naming the
 * type. Unions, maps, bitsets and bitmasks are not supported (the viscera
 * IDL has none). */
#ifndef VISCERA_REC_TYPES_H
#define VISCERA_REC_TYPES_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "recording/recfile.h"
#include "verr.h"

#define RT_MAX_DEPTH 16
#define RT_MAX_DIMS 4

typedef enum rt_kind {
  RT_BOOL,
  RT_OCTET,
  RT_CHAR,
  RT_INT8,
  RT_UINT8,
  RT_INT16,
  RT_UINT16,
  RT_INT32,
  RT_UINT32,
  RT_INT64,
  RT_UINT64,
  RT_FLOAT32,
  RT_FLOAT64,
  RT_STRING,
  RT_ENUM,
  RT_STRUCT,
  RT_SEQUENCE,
  RT_ARRAY
} rt_kind_t;

typedef enum rt_ext { RT_FINAL, RT_APPENDABLE, RT_MUTABLE } rt_ext_t;

typedef struct rt_type rt_type_t;

typedef struct rt_member {
  char *name;
  bool key;
  bool optional;
  uint32_t id; /* member id (mutable types) */
  const rt_type_t *type;
} rt_member_t;

typedef struct rt_literal {
  char *name;
  int32_t value;
} rt_literal_t;

struct rt_type {
  rt_kind_t kind;
  char *name;     /* struct, enum: qualified name "viscera::ToolCommand"; else NULL */
  uint32_t bound; /* string, sequence: 0 = unbounded */
  uint32_t dims[RT_MAX_DIMS];
  int ndims;             /* array */
  const rt_type_t *elem; /* sequence, array */
  rt_ext_t ext;          /* struct */
  const rt_type_t *base; /* struct: inherited members come first, NULL none */
  rt_member_t *members;  /* struct */
  uint32_t nmembers;
  rt_literal_t *literals; /* enum */
  uint32_t nliterals;
  uint16_t bit_bound; /* enum: 8, 16 or 32 */
};

typedef struct rt_model {
  rt_type_t **types; /* every node, owned */
  size_t ntypes, cap;
  const rt_type_t *top; /* the topic's type */
} rt_model_t;

/* Builds the model of type `type_name` from a serialized XTypes type
 * mapping (what dds_topic_descriptor_t.type_mapping holds). 0, or -1 with
 * err; the model must be freed with rt_model_free either way. */
int rt_model_load(rt_model_t *m, const void *typemap, size_t len, const char *type_name, verr_t *err);

/* Same, for a recorded topic (its stored typemap and type name). */
int rt_model_load_topic(rt_model_t *m, recfile_t *rf, const recfile_topic_t *t, verr_t *err);

void rt_model_free(rt_model_t *m);

/* The literal of an enum value, NULL when it has none. */
const char *rt_enum_name(const rt_type_t *e, int32_t value);

/* A growing text buffer for the writers of IDL, JSON and CSV text: `oom`
 * sticks once an append failed; s is "" or NUL-terminated. */
typedef struct rt_str {
  char *s;
  size_t len, cap;
  bool oom;
} rt_str_t;
void rt_str_printf(rt_str_t *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
void rt_str_append(rt_str_t *b, const char *s, size_t len);
void rt_str_free(rt_str_t *b);

#endif
