/* SPDX-License-Identifier: Apache-2.0 */
/* store: writes a session recording (format in recording.h) to one SQLite
 * file, with batched transactions.
 *
 * Samples are inserted inside an open transaction that is committed when it
 * is older than the batch interval or holds too many samples or bytes, so a
 * kill -9 loses at most one batch, never corrupts the file (WAL journal,
 * synchronous=NORMAL: committed batches survive a process crash; a power
 * loss may also drop the last few), and memory stays bounded whatever the
 * data rate (SQLite spills a big transaction to the WAL file).
 *
 * Not thread-safe: one thread owns a store. Every function returns 0 on
 * success or -1 with `err` naming the file and the SQLite error.
 *
 * A failed write (disk full, I/O error) stops the store cleanly: the open
 * batch is lost, every committed one stays readable, nothing crashes; see
 * store_failed. */
#ifndef VISCERA_REC_STORE_H
#define VISCERA_REC_STORE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <dds/dds.h>

#include "verr.h"

typedef struct store store_t;

typedef struct store_session {
  const char *scene;     /* may be NULL */
  const char *partition; /* the partition pattern recorded */
  int domain;
  int64_t start_wall_ns;
  const char *hostname; /* may be NULL */
  const char *recorder_version;
} store_session_t;

/* When a batch is committed: whichever limit is reached first. */
typedef struct store_batch_limits {
  uint64_t max_age_ns;
  uint32_t max_samples;
  uint64_t max_bytes;
} store_batch_limits_t;

/* 200 ms, 2000 samples, 32 MB. */
#define STORE_DEFAULT_LIMITS ((store_batch_limits_t){200000000u, 2000u, 32u * 1024u * 1024u})

typedef struct store_sample {
  int64_t topic_id;
  int64_t writer_id; /* <= 0: unknown writer, stored as NULL */
  int64_t source_ts_ns;
  int64_t recv_wall_ns;
  int kind; /* rec_kind_t */
  bool inferred;
  const void *cdr;
  size_t cdr_len;
} store_sample_t;

/* Creates `path` and writes the schema and the session row. Refuses an
 * existing file (or a stale "-wal" next to it) unless `force`, in which case
 * they are removed first. */
int store_open(store_t **out, const char *path, bool force, const store_session_t *meta, verr_t *err);

void store_set_limits(store_t *s, store_batch_limits_t limits);

/* Adds a topic: descriptor fields (ops counted with dds_stream_countops),
 * its keys, and the QoS `qos` (normally the first writer's; NULL allowed).
 * Sets *id to the topic id used by store_add_writer/store_add_sample. */
int store_add_topic(store_t *s, const char *name, const dds_topic_descriptor_t *desc, const dds_qos_t *qos,
                    int64_t wall_ns, int64_t *id, verr_t *err);

/* Adds a writer of a stored topic; `guid` is 16 bytes, `partitions` may be NULL. */
int store_add_writer(store_t *s, int64_t topic_id, const uint8_t guid[16], const char *partitions, int64_t wall_ns,
                     int64_t *id, verr_t *err);

/* Records a participant of the domain (recording.h, table participants):
 * `user_data` and `role` must already be sanitized text (vdds_ident.h), role
 * may be NULL. Alive: inserted with first/last seen = wall_ns, or its text
 * and last seen updated (a participant that came back is no longer "left").
 * Not alive (`left`): last seen and left time set to wall_ns. */
int store_note_participant(store_t *s, const uint8_t guid[16], const char *user_data, const char *role, bool left,
                           int64_t wall_ns, verr_t *err);
/* Sets the verified certificate subject of a participant already noted
 * (column participants.subject; see vdds_subject.h for what is verified). */
int store_note_subject(store_t *s, const uint8_t guid[16], const char *subject, verr_t *err);

/* Appends one sample to the current batch (starting one if needed); commits
 * at once when the batch reaches its sample or byte limit. */
int store_add_sample(store_t *s, const store_sample_t *smp, verr_t *err);

/* Commits the current batch if it is older than the age limit. */
int store_commit_if_due(store_t *s, uint64_t now_mono_ns, verr_t *err);
/* Commits the current batch, if any. */
int store_commit(store_t *s, verr_t *err);

/* Samples and CDR bytes stored so far (including the open batch). */
void store_counts(const store_t *s, uint64_t *samples, uint64_t *bytes);

/* A write failed (e.g. disk full, file-size limit): the store has stopped.
 * The open batch was rolled back, store_counts report what the file holds,
 * and every later write fails with the same message. */
bool store_failed(const store_t *s);
/* ... and the cause was a full disk, a quota or a file-size limit. */
bool store_disk_full(const store_t *s);

/* Commits, writes the end time, builds the indexes and closes. Frees `s`
 * even on failure. With end_wall_ns < 0 the end time stays NULL (used by
 * tests to imitate a killed recorder). A stopped store (store_failed) is
 * closed best effort without an end time, its WAL checkpointed into the
 * file where there is room; it returns -1 with the failure. */
int store_close(store_t *s, int64_t end_wall_ns, verr_t *err);

/* Formats a 16-byte GUID as 32 lower-case hex digits plus NUL. */
void store_guid_hex(const uint8_t guid[16], char out[33]);

#endif
