/* SPDX-License-Identifier: Apache-2.0 */
/* recinfo_export: viscera-recinfo --export: a recording in formats other
 * tools read, from the recording alone (types from its stored type
 * information, rec_types.h; no compiled-in type).
 *   mcap   every topic: one schema per type (its OMG IDL text, encoding
 *          "omgidl"), one channel per topic and partition (message
 *          encoding "cdr", metadata dds_topic, partition, type), every
 *          data sample as recorded (CDR with its encoding header), log and
 *          publish time = the sample's source time (ns since the epoch).
 *          Dispose and unregister rows carry no message and are counted.
 *          With `scene`, the organ meshes also as Foxglove scene
 *          primitives on one more channel (export_scene.h).
 *   csv    one topic (--topic): a header, then one row per data sample:
 *          source_time_ns, partition, then the decoded fields (rec_cdr.h).
 *   jsonl  one topic: one JSON object per data sample,
 *          {"source_time_ns":N,"partition":"P","sample":{...}}.
 * OUT "-" writes csv/jsonl to stdout. */
#ifndef VISCERA_RECINFO_EXPORT_H
#define VISCERA_RECINFO_EXPORT_H

#include <stdbool.h>

typedef enum export_format { EXPORT_NONE, EXPORT_MCAP, EXPORT_CSV, EXPORT_JSONL } export_format_t;

/* "mcap", "csv", "jsonl" -> the format; EXPORT_NONE when unknown. */
export_format_t export_format_parse(const char *name);

/* Exit code: 0 all exported; 1 unreadable recording, unwritable OUT, or
 * samples that did not decode (the others are exported); 2 no such topic
 * or no --topic for csv/jsonl. A summary goes to stderr unless quiet. */
int recinfo_export(const char *path, export_format_t fmt, const char *out, const char *topic, bool scene, bool quiet);

#endif
