/* SPDX-License-Identifier: Apache-2.0 */
/* rec_taken: the step that took each tool command, as a recording's
 * AppliedInput tells it (the integration checkers rec_tools and
 * rec_feedback_first judge the ContactFeedback answers against it).
 *
 * An AppliedInput sample lists the command each tool took before a step;
 * its sim_time_ns is the simulated time at that step's start. Read here per
 * tool (ids below REC_TAKEN_TOOLS, others ignored) in recording order,
 * samples of a paused session (no step taken) and released tools skipped.
 * Reading is strict as rec_read.h's is. Single-threaded test code; the
 * caller owns the struct and frees it with rec_taken_free. */
#ifndef VISCERA_TEST_REC_TAKEN_H
#define VISCERA_TEST_REC_TAKEN_H

#include <stdint.h>

#include "recording/recfile.h"

#define REC_TAKEN_TOOLS 8

typedef struct rec_taken_cmd {
  uint64_t seq;      /* the command's cmd_seq */
  uint64_t start_ns; /* sim time at the start of the step that took it */
  double move;       /* m the tip moved since the tool's previous taken command (0: its first, or after a release) */
} rec_taken_cmd_t;

typedef struct rec_taken {
  rec_taken_cmd_t *cmd[REC_TAKEN_TOOLS]; /* per tool, in the order taken */
  size_t n[REC_TAKEN_TOOLS];
  uint64_t dt_ns; /* step length: sim time / steps of the first sample after a step (paused too); 0: none */
  int oom;        /* out of memory while reading: the lists stop short */
  /* reader's state */
  size_t cap[REC_TAKEN_TOOLS], cursor[REC_TAKEN_TOOLS];
  double prev[REC_TAKEN_TOOLS][3]; /* the tip's last applied position */
  int has_prev[REC_TAKEN_TOOLS];
} rec_taken_t;

/* Reads the topic viscera_AppliedInput of `rf` into `t` (zeroed first).
 * Returns the problems met as rec_read_topic counts them (reported on
 * stderr prefixed with `tool`), plus one when out of memory (t->oom). */
int rec_taken_read(const char *tool, recfile_t *rf, rec_taken_t *t);

/* Whether command `seq` of tool `tool` was taken in the step starting at
 * `start_ns`; 0 when the tool never took it. Asked in the order the
 * commands were taken (answers come in that order), it is a cursor that
 * moves on from the last command found, not a search from the start. */
int rec_taken_in(rec_taken_t *t, unsigned tool, uint64_t seq, uint64_t start_ns);

void rec_taken_free(rec_taken_t *t);

#endif
