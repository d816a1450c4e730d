/* SPDX-License-Identifier: Apache-2.0 */
/* rec_decode: turns the raw CDR stored in a recording back into the
 * compiled-in IDL types (viscera.h), for programs that know the product
 * types: the report tool, viscera-resim and the integration-test readers.
 * The recorder itself stays generic and never links this.
 *
 * Nothing stored is trusted: every sample is normalized (all lengths, enum
 * values and string bounds checked against the type) before it is read, so
 * a garbled or foreign sample is reported as undecodable, never read out of
 * bounds; a blob of only zero bytes (a zero-filled page of a damaged file)
 * is refused too. A sample whose writer used a newer type (e.g. an enum value this
 * build does not know) does not decode either; callers count and report it
 * instead of failing. Not thread-safe per sample buffer; no global state. */
#ifndef VISCERA_REC_DECODE_H
#define VISCERA_REC_DECODE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <dds/dds.h>

#include "recording/recfile.h"

/* Decodes one stored sample (4-byte encoding header + payload) into `out`
 * (desc->m_size bytes). `out` is zeroed first, so it may be an uninitialized
 * local; whatever it held before is overwritten, not freed (free a decoded
 * sample with rec_decode_free before reusing it). Returns false when it does
 * not decode; `out` is then zeroed and holds nothing to free. */
bool rec_decode_cdr(const void *cdr, size_t len, const dds_topic_descriptor_t *desc, void *out);

/* Frees what a decoded sample owns (sequences, unbounded strings) and zeroes
 * it, so the buffer can take the next sample. */
void rec_decode_free(void *sample, const dds_topic_descriptor_t *desc);

/* The value of enum literal `literal` (e.g. "EVENT_TASK_STARTED") in any
 * enum of the descriptor's compiled type information. Lets a reader use
 * enum values added after it was written without naming them in code.
 * Returns false when the type has no such literal. */
bool rec_decode_enum_value(const dds_topic_descriptor_t *desc, const char *literal, int32_t *value);

typedef struct rec_decode_report {
  recfile_scan_report_t scan; /* what reading the rows met */
  uint64_t decoded;           /* data samples delivered */
  uint64_t undecodable;       /* data samples that did not decode */
  int64_t first_undecodable;  /* row id of the first of them, 0 when none */
  bool topic_missing;         /* the recording has no such topic */
} rec_decode_report_t;

/* Return non-zero to stop. `sample` is valid during the call only. */
typedef int (*rec_decode_cb)(void *arg, const void *sample, const recfile_row_t *row);

/* Calls `cb` for every data sample of topic `topic` (e.g.
 * "viscera_ContactFeedback") that decodes with `desc`, in recording order,
 * salvaging around damage (recfile_scan). Dispose/unregister rows are
 * skipped. A topic recorded with an older version of the type (format 1 or
 * 2, before fields were appended to it: no row decodes with `desc`, rows do
 * with a frozen twin, idl/viscera_format2.idl tried before
 * idl/viscera_format1.idl) is read with that twin into the prefix of desc's
 * struct, the appended fields zero.
 * Returns 0, or -1 when out of memory. */
int rec_decode_topic(recfile_t *rf, const char *topic, const dds_topic_descriptor_t *desc, rec_decode_cb cb, void *arg,
                     rec_decode_report_t *rep);

#endif
