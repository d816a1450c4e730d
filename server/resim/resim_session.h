/* SPDX-License-Identifier: Apache-2.0 */
/* resim_session: which of a recording's samples belong to the session to
 * re-simulate. A lab's recording (deploy/lab.sh: one recorder of all its seats)
 * holds every seat's session, each seat's server writing in its own
 * partition (PREFIX/seatNN); mixing them would re-apply one seat's inputs
 * and compare them against every seat's frames. The session is chosen by
 * partition: the one asked for, or the recording's only one.
 *
 * A session may also hold several runs of its server: a recorder that kept
 * going while the server was killed and restarted (resumed from its
 * checkpoint, or from rest) records both, each numbering its steps and
 * inputs on its own. Each run is one server participant (its writers' GUIDs
 * share the participant's 12-byte prefix); one run is re-simulated, the last
 * unless asked, with the samples of the others left out. Other writers of
 * the session (the haptic clients) stay in every run.
 *
 * Untrusted input: writer ids and partition texts come from the file; ids
 * are kept in a sorted array (no table indexed by a stored number).
 * Ownership: a resim_session_t owns its id array (resim_session_free).
 * Not thread-safe. */
#ifndef VISCERA_RESIM_SESSION_H
#define VISCERA_RESIM_SESSION_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "recording/recfile.h"
#include "verr.h"

typedef struct resim_session {
  bool filter;  /* false: every sample (a recording of one session, no partition asked) */
  int64_t *ids; /* the chosen session's writers, sorted ascending */
  size_t n;
  char partition[256]; /* the chosen partition, "" when not filtering */
  size_t nruns;        /* server runs in the session (participants writing its SceneInfo) */
  size_t run;          /* the run kept, 1..nruns; 0 when the session holds one run (nothing left out) */
} resim_session_t;

/* Picks the session of `partition` (NULL or "": the recording must hold
 * one session, i.e. its SceneInfo writers are all in one partition), and
 * in it server run `run` (1 = the first; 0 = the last).
 * Returns 0, or -1 with err naming the partitions the recording holds (a
 * recording of several sessions and no partition asked, a partition it
 * does not hold, out of memory, an unreadable writers table) or the number
 * of runs (a run it does not hold). */
int resim_session_pick(recfile_t *rf, const char *partition, size_t run, resim_session_t *out, verr_t *err);

/* True when a sample of writer `writer_id` belongs to the session. */
bool resim_session_has(const resim_session_t *s, int64_t writer_id);

void resim_session_free(resim_session_t *s);

#endif
