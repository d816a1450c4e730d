/* SPDX-License-Identifier: Apache-2.0 */
/* session: one recording session — a DDS participant in the recorded
 * domain, the partition it listens to, the topics found so far and the
 * store they are written to.
 *
 * Flow per step: discovery reports writers in the partition; a writer on a
 * new topic has its type resolved from its XTypes type information (never
 * from compiled-in types) and gets a capture; a writer on a known topic is
 * added to that capture; then every capture is drained into the store and
 * the batch is committed when due. A topic whose type cannot be resolved
 * is reported on the log and skipped; the others keep recording.
 *
 * Not thread-safe: one thread drives a session. */
#ifndef VISCERA_REC_SESSION_H
#define VISCERA_REC_SESSION_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include <dds/dds.h>

#include "verr.h"

typedef struct rec_session_opts {
  int domain;
  const char *partition; /* pattern, fnmatch(3) syntax */
  const char *scene;     /* metadata only; may be NULL */
  const char *out;       /* database file */
  bool force;            /* replace an existing file */
  int32_t depth;         /* reader keep-last depth; <= 0: CAPTURE_DEFAULT_DEPTH */
  /* One type-lookup attempt waits this long; attempts repeat every
   * type_retry until type_give_up after the writer was seen. */
  dds_duration_t type_attempt;
  dds_duration_t type_retry;
  dds_duration_t type_give_up;
  FILE *log; /* warnings and topic announcements; NULL: silent */
} rec_session_opts_t;

#define REC_SESSION_DEFAULT_TYPE_ATTEMPT DDS_MSECS(200)
#define REC_SESSION_DEFAULT_TYPE_RETRY DDS_MSECS(500)
#define REC_SESSION_DEFAULT_TYPE_GIVE_UP DDS_SECS(10)

typedef struct rec_session rec_session_t;

typedef struct rec_session_stats {
  uint64_t samples; /* rows stored */
  uint64_t bytes;   /* CDR bytes stored */
  uint32_t topics;  /* topics being recorded */
  uint32_t failed_topics;
  bool disk_full; /* recording stopped because the disk (or file-size limit) was full */
} rec_session_stats_t;

/* Creates the store first (so a bad --out fails before touching DDS), then
 * the participant and the partitioned subscriber. */
int rec_session_open(rec_session_t **out, const rec_session_opts_t *opts, const char *recorder_version, verr_t *err);

/* Waits up to `timeout` for discovery or data, then processes everything
 * pending. Returns -1 only on errors that stop the recording (the store
 * failed); per-topic problems go to the log. */
int rec_session_step(rec_session_t *s, dds_duration_t timeout, verr_t *err);

void rec_session_get_stats(const rec_session_t *s, rec_session_stats_t *st);

/* Takes what is left, commits, writes the end time and closes the file
 * and the participant; fills `final` (may be NULL) with the totals after
 * that last drain. Frees `s` even on failure. */
int rec_session_close(rec_session_t *s, rec_session_stats_t *final, verr_t *err);

#endif
