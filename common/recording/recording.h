/* SPDX-License-Identifier: Apache-2.0 */
/* recording: the on-disk format of a viscera session recording.
 *
 * One SQLite file per session, written by viscera-recorder (store.c) and read
 * by viscera-recinfo and replay (recfile.c). The file is self-describing: it
 * holds every topic's type descriptor and QoS next to the raw CDR of every
 * sample, so a recording can be replayed or decoded without the program that
 * produced it.
 *
 * Identification: PRAGMA application_id = REC_APPLICATION_ID and
 * PRAGMA user_version = REC_FORMAT_VERSION. Readers accept files whose
 * tables are present even if the pragmas were lost (e.g. a file copied
 * through a tool that rewrote it), but tell the user.
 *
 * Tables (see REC_SCHEMA_SQL for the exact DDL):
 *   session     exactly one row: format version, scene, partition pattern,
 *               domain, start/end wall time (ns since the Unix epoch; end is
 *               NULL while recording or when the recorder was killed),
 *               hostname, recorder and Cyclone DDS versions.
 *   topics      one row per recorded topic: name, type name, the fields of
 *               dds_topic_descriptor_t needed to rebuild it (size, align,
 *               flagset, ops as little-endian uint32 words counted with
 *               dds_stream_countops, XTypes type information and type
 *               mapping bytes, restrict_data_representation) and the QoS
 *               of the first writer seen (what a replay writer should use).
 *   topic_keys  the key descriptors (m_keys) of each topic, in order.
 *   writers     one row per DDS writer heard: GUID (32 hex digits), topic,
 *               its partitions (comma separated), first-seen wall time.
 *   participants  one row per DDS participant seen in the domain (from the
 *               DCPSParticipant built-in topic): GUID (32 hex digits), its
 *               USER_DATA as sanitized printable text (viscera processes
 *               announce "viscera role=R [tool=N ]host=H pid=P", see
 *               vdds_ident.h; the role is a claim, not an authenticated
 *               identity), the role parsed from it (NULL if none), first and
 *               last seen wall time and the time it left (disposed or its
 *               lease expired; NULL if still there at the end). Added after
 *               format 1 shipped: files without this table stay valid and
 *               readers treat it as optional. `subject` (added later still,
 *               NULL in older files) is the participant's certificate
 *               subject (RFC 2253) when the recorder ran with DDS Security
 *               and the announced subject matched the authenticated GUID
 *               (vdds_subject.h); NULL otherwise.
 *   sample_kinds  lookup table naming the values of samples.kind.
 *   samples     one row per sample in the order the recorder stored it:
 *               topic, writer, source timestamp (writer's clock, ns), wall
 *               time the recorder took the sample from DDS (ns), kind (data / dispose / unregister),
 *               `inferred` (1 when the dispose/unregister was not delivered
 *               as its own sample but read from the instance state of the
 *               instance's latest data sample; its timestamps are those of
 *               that sample), and the CDR bytes including the 4-byte
 *               encoding header. Dispose and unregister rows hold the
 *               serialized key (or the full sample when inferred). Their
 *               source timestamp is what Cyclone reports: the dispose
 *               time for an explicit dispose, but the instance's last
 *               update time when the end is derived from the writer
 *               leaving (deleted, or its lease expired); so only data
 *               rows are guaranteed monotonic per writer.
 *
 * Durability: WAL journal, samples committed in batches. A killed recorder
 * loses at most the last uncommitted batch; the file stays consistent. */
#ifndef VISCERA_RECORDING_H
#define VISCERA_RECORDING_H

/* 'VSCR' */
#define REC_APPLICATION_ID 0x56534352
#define REC_FORMAT_VERSION 1

typedef enum rec_kind { REC_KIND_DATA = 0, REC_KIND_DISPOSE = 1, REC_KIND_UNREGISTER = 2 } rec_kind_t;

/* The tables every recording has; a reader checks for all of them. */
#define REC_REQUIRED_TABLES                                                                                            \
  { "session", "topics", "writers", "samples" }
#define REC_REQUIRED_TABLE_COUNT 4

#define REC_SCHEMA_SQL                                                                                                 \
  "CREATE TABLE session ("                                                                                             \
  " format_version INTEGER NOT NULL,"                                                                                  \
  " scene TEXT,"                                                                                                       \
  " partition TEXT NOT NULL,"                                                                                          \
  " domain INTEGER NOT NULL,"                                                                                          \
  " start_wall_ns INTEGER NOT NULL,"                                                                                   \
  " end_wall_ns INTEGER,"                                                                                              \
  " hostname TEXT,"                                                                                                    \
  " recorder_version TEXT NOT NULL,"                                                                                   \
  " dds_version TEXT);"                                                                                                \
  "CREATE TABLE topics ("                                                                                              \
  " id INTEGER PRIMARY KEY,"                                                                                           \
  " name TEXT NOT NULL UNIQUE,"                                                                                        \
  " type_name TEXT NOT NULL,"                                                                                          \
  " desc_size INTEGER NOT NULL,"                                                                                       \
  " desc_align INTEGER NOT NULL,"                                                                                      \
  " desc_flagset INTEGER NOT NULL,"                                                                                    \
  " nkeys INTEGER NOT NULL,"                                                                                           \
  " nops INTEGER NOT NULL,"                                                                                            \
  " ops BLOB NOT NULL,"                                                                                                \
  " typeinfo BLOB,"                                                                                                    \
  " typemap BLOB,"                                                                                                     \
  " restrict_data_representation INTEGER NOT NULL,"                                                                    \
  " reliability TEXT NOT NULL,"                                                                                        \
  " max_blocking_ns INTEGER,"                                                                                          \
  " durability TEXT NOT NULL,"                                                                                         \
  " history TEXT NOT NULL,"                                                                                            \
  " history_depth INTEGER,"                                                                                            \
  " durability_service_history TEXT,"                                                                                  \
  " durability_service_depth INTEGER,"                                                                                 \
  " deadline_ns INTEGER,"                                                                                              \
  " liveliness TEXT,"                                                                                                  \
  " liveliness_lease_ns INTEGER,"                                                                                      \
  " ownership TEXT,"                                                                                                   \
  " ownership_strength INTEGER,"                                                                                       \
  " data_representation TEXT,"                                                                                         \
  " discovered_wall_ns INTEGER NOT NULL);"                                                                             \
  "CREATE TABLE topic_keys ("                                                                                          \
  " topic_id INTEGER NOT NULL REFERENCES topics(id),"                                                                  \
  " idx INTEGER NOT NULL,"                                                                                             \
  " name TEXT NOT NULL,"                                                                                               \
  " offset INTEGER NOT NULL,"                                                                                          \
  " key_index INTEGER NOT NULL,"                                                                                       \
  " PRIMARY KEY (topic_id, idx));"                                                                                     \
  "CREATE TABLE writers ("                                                                                             \
  " id INTEGER PRIMARY KEY,"                                                                                           \
  " topic_id INTEGER NOT NULL REFERENCES topics(id),"                                                                  \
  " guid TEXT NOT NULL,"                                                                                               \
  " partitions TEXT,"                                                                                                  \
  " first_seen_wall_ns INTEGER NOT NULL,"                                                                              \
  " UNIQUE (topic_id, guid));"                                                                                         \
  "CREATE TABLE participants ("                                                                                        \
  " guid TEXT PRIMARY KEY,"                                                                                            \
  " user_data TEXT,"                                                                                                   \
  " role TEXT,"                                                                                                        \
  " first_seen_wall_ns INTEGER NOT NULL,"                                                                              \
  " last_seen_wall_ns INTEGER NOT NULL,"                                                                               \
  " left_wall_ns INTEGER,"                                                                                             \
  " subject TEXT);"                                                                                                    \
  "CREATE TABLE sample_kinds (id INTEGER PRIMARY KEY, name TEXT NOT NULL);"                                            \
  "INSERT INTO sample_kinds VALUES (0, 'data'), (1, 'dispose'), (2, 'unregister');"                                    \
  "CREATE TABLE samples ("                                                                                             \
  " id INTEGER PRIMARY KEY,"                                                                                           \
  " topic_id INTEGER NOT NULL REFERENCES topics(id),"                                                                  \
  " writer_id INTEGER REFERENCES writers(id),"                                                                         \
  " source_ts_ns INTEGER NOT NULL,"                                                                                    \
  " recv_wall_ns INTEGER NOT NULL,"                                                                                    \
  " kind INTEGER NOT NULL REFERENCES sample_kinds(id),"                                                                \
  " inferred INTEGER NOT NULL DEFAULT 0,"                                                                              \
  " cdr BLOB NOT NULL);"

/* Built once at a clean close (cheaper than maintaining them per insert);
 * a killed recording has none, and readers must not depend on them. */
#define REC_INDEX_SQL "CREATE INDEX IF NOT EXISTS samples_by_topic ON samples (topic_id, source_ts_ns);"

#endif
