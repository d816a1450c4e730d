/* SPDX-License-Identifier: Apache-2.0 */
/* rec_cdr: stored CDR samples decoded with the recorded type (rec_types.h)
 * into text, for viscera-recinfo --export csv / jsonl: no compiled-in type
 * is used, so any recorded topic decodes as it was written.
 *
 * Encodings: XCDR1 (plain CDR) and XCDR2 (with the DHEADER of appendable
 * structs and of collections of non-primitive elements), either byte order;
 * mutable structs (parameter lists) are refused. Members an appendable
 * sample written with an older type lacks are null (JSON) or empty (CSV);
 * members a newer writer appended are skipped. Nothing is trusted: every
 * length is checked against the bytes left and the type's bounds, strings
 * must be NUL-terminated, and a sample that does not fit its type is an
 * error naming the member. */
#ifndef VISCERA_REC_CDR_H
#define VISCERA_REC_CDR_H

#include "recording/rec_types.h"

/* One JSON object, members by name in type order; enums as their literal
 * name, non-finite floats as null, octet and char sequences as arrays. */
int rt_cdr_json(const rt_type_t *top, const void *cdr, size_t len, rt_str_t *out, verr_t *err);

/* CSV: nested structs flatten to "a.b" columns, arrays of up to
 * RT_CSV_MAX_SPLIT scalars to "a[0]", "a[1]", ... columns; sequences and
 * anything else is one column holding its JSON text. The header and the
 * rows use the same order. Neither writes the line end. */
#define RT_CSV_MAX_SPLIT 16
void rt_csv_header(const rt_type_t *top, rt_str_t *out);
int rt_cdr_csv(const rt_type_t *top, const void *cdr, size_t len, rt_str_t *out, verr_t *err);

/* The scalar members of a sample (nested structs as "a.b"; collections are
 * skipped), in type order, each once: `num` holds numbers, booleans (0/1)
 * and enum values, `str` the text (strings as they are, enum literals,
 * numbers as printed), valid during the call. Members the sample lacks
 * (written with an older, shorter type) are not visited. Lets a reader
 * take fields by name from a sample its compiled type cannot decode. */
typedef struct rt_field {
  const char *path;
  const rt_type_t *type;
  double num;
  const char *str;
} rt_field_t;
typedef void (*rt_field_cb)(void *arg, const rt_field_t *f);
int rt_cdr_fields(const rt_type_t *top, const void *cdr, size_t len, rt_field_cb cb, void *arg, verr_t *err);

/* The sample re-encoded as XCDR1 (plain CDR, encoding header CDR_LE or
 * CDR_BE in the sample's byte order) into `out` (binary: 4-byte header +
 * payload, appended), for readers that cannot take XCDR2 (the MCAP export:
 * docs/dds.md "Schema evolution"). XCDR1 has no DHEADER, so an appendable
 * struct encodes there as a final one: members an older writer's sample
 * lacks get their default (0, "", empty, an enum's first literal), members
 * a newer writer appended are dropped. An XCDR1 sample is copied as it is.
 * The sample is checked as Cyclone's own reader checks it (lengths, bounds,
 * booleans, enum values the type has); on error `out` is left as it was. */
int rt_cdr_to_xcdr1(const rt_type_t *top, const void *cdr, size_t len, rt_str_t *out, verr_t *err);

#endif
