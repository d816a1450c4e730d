/* SPDX-License-Identifier: Apache-2.0 */
/* recfile: reads a session recording (format in recording.h) defensively.
 *
 * Opening tells a missing file, a file that is not SQLite, a SQLite file
 * that is not a viscera recording and a damaged one apart, each with a
 * message naming the file. Scanning salvages: when SQLite reports damage
 * part-way through the samples, the scan skips ahead past the damaged
 * region and reports how it went instead of failing outright. Nothing here
 * trusts the file: every length and value read is checked before use.
 *
 * Opened read-only; a recording that is still being written can be read
 * (WAL readers do not block the writer). Not thread-safe. */
#ifndef VISCERA_REC_RECFILE_H
#define VISCERA_REC_RECFILE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "verr.h"

typedef struct recfile recfile_t;

typedef struct recfile_session {
  bool valid; /* false when the session row could not be read */
  int format_version;
  char scene[128];
  char partition[256];
  int domain;
  int64_t start_wall_ns;
  bool has_end; /* false: recorder killed or still running */
  int64_t end_wall_ns;
  char hostname[128];
  char recorder_version[64];
  char dds_version[64];
} recfile_session_t;

typedef struct recfile_topic {
  int64_t id;
  char name[256];
  char type_name[256];
  char reliability[24];
  char durability[24];
  int64_t writers; /* rows in `writers` for it; -1 unknown */
} recfile_topic_t;

typedef struct recfile_row {
  int64_t id;
  int64_t topic_id;
  int64_t writer_id; /* 0 when unknown (NULL) */
  int64_t source_ts_ns;
  int64_t recv_wall_ns;
  int kind;
  bool inferred;
  size_t cdr_len;
  const void *cdr; /* only when the scan asked for it; valid during the callback */
} recfile_row_t;

typedef struct recfile_scan_report {
  uint64_t rows;    /* rows delivered to the callback */
  uint64_t invalid; /* rows read but impossible (zeroed or garbled page): skipped */
  uint32_t damaged; /* errors met (0: the whole table was read) */
  bool gave_up;     /* could not get past a damaged region */
  char first_error[256];
} recfile_scan_report_t;

/* Returns 0, or -1 with err = "<path>: <what is wrong>". */
int recfile_open(recfile_t **out, const char *path, verr_t *err);
void recfile_close(recfile_t *rf);

const char *recfile_path(const recfile_t *rf);
const recfile_session_t *recfile_session(const recfile_t *rf);
size_t recfile_topic_count(const recfile_t *rf);
const recfile_topic_t *recfile_topic(const recfile_t *rf, size_t i);
/* NULL when absent. */
const recfile_topic_t *recfile_topic_by_name(const recfile_t *rf, const char *name);
/* Non-fatal problems met while opening (e.g. unreadable session row,
 * missing identification pragmas), "" when none. */
const char *recfile_warnings(const recfile_t *rf);
/* True when opening met damage (truncation, unreadable metadata): what is
 * reported is a salvage, not the whole recording. */
bool recfile_damaged(const recfile_t *rf);

/* The open SQLite handle (a `sqlite3 *`), for readers of the tables this
 * API does not wrap (rec_writers.h, rec_schema.h); read-only, owned by rf. */
void *recfile_sqlite(recfile_t *rf);

/* Return non-zero to stop the scan. */
typedef int (*recfile_row_cb)(void *arg, const recfile_row_t *row);

/* Calls `cb` for every readable sample in insertion order, of topic
 * `topic_id` only when > 0, with the CDR bytes when `with_cdr`. Rows that
 * cannot be real (topic id < 1, unknown kind, negative length: what a
 * zero-filled or garbled page yields) are counted in rep->invalid, not
 * delivered. */
void recfile_scan(recfile_t *rf, int64_t topic_id, bool with_cdr, recfile_row_cb cb, void *arg,
                  recfile_scan_report_t *rep);

/* One row of the optional participants table (recording.h). Text is
 * re-sanitized on read (the file is untrusted too) and bounded. */
typedef struct recfile_participant {
  char guid[33];
  char user_data[256];
  char role[32]; /* "" when none was announced */
  int64_t first_seen_wall_ns, last_seen_wall_ns;
  int64_t left_wall_ns; /* < 0: still present at the end */
  char subject[160];    /* verified certificate subject, "" when none (not secure, or an older file) */
} recfile_participant_t;
typedef void (*recfile_participant_cb)(void *arg, const recfile_participant_t *p);
/* Calls cb for each participant, in first-seen order. Returns the count,
 * or -1 when the file has no participants table (recorded before it
 * existed), or -2 when the table cannot be read (damaged). */
int recfile_participants(recfile_t *rf, recfile_participant_cb cb, void *arg);

#endif
