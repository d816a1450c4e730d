/* SPDX-License-Identifier: Apache-2.0 */
/* rec_writers: the writers table of a recording (recording.h), and who
 * each writer belongs to: its partitions (a lab recording's seats) and the
 * participant that owns it (the identity that participant announced).
 *
 * Read-only and defensive like recfile: text is re-sanitized and bounded; a
 * recording without the participants table still lists its writers, with
 * no identity. */
#ifndef VISCERA_REC_WRITERS_H
#define VISCERA_REC_WRITERS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "recording/recfile.h"
#include "verr.h"

typedef struct rec_writer {
  int64_t id;
  int64_t topic_id;
  char guid[33];         /* 32 hex digits */
  char partitions[256];  /* comma separated, as recorded ("" when none) */
  char participant[256]; /* USER_DATA of the owning participant, "" unknown */
  char role[32];         /* its role, "" unknown */
  char subject[160];     /* its verified certificate subject, "" none (recfile.h) */
} rec_writer_t;

/* Every writer, ordered by id, into *out (*n of them; free(*out)).
 * Returns 0, or -1 with err when the table cannot be read. */
int rec_writers_load(recfile_t *rf, rec_writer_t **out, size_t *n, verr_t *err);

/* The writer of that id in a list from rec_writers_load, NULL when absent. */
const rec_writer_t *rec_writer_find(const rec_writer_t *w, size_t n, int64_t id);

/* The value of `key=` in a USER_DATA text ("viscera role=haptic host=h
 * station=s ..."), copied into out; false when absent. */
bool rec_ident_field(const char *user_data, const char *key, char *out, size_t size);

#endif
