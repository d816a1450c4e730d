/* SPDX-License-Identifier: Apache-2.0 */
/* replay_run: viscera-replay once its options are parsed: open the
 * recording, set up its topics (replay_topic.h), publish its samples in
 * recorded (insertion) order at their original pace (source timestamps,
 * scaled by --speed; replay_write.h), pause and resume on SIGUSR1 or
 * --pause-at (replay_pause.h), start over with --loop, and print the
 * summary. */
#ifndef VISCERA_REPLAY_RUN_H
#define VISCERA_REPLAY_RUN_H

#include <stdbool.h>

typedef struct replay_options {
  const char *path;    /* the recording */
  int domain;          /* --domain; -1: the recorded one */
  char partition[256]; /* --partition; "": the recorded one (refused when it is a pattern) */
  double speed, seek;  /* --speed (> 0), --seek S */
  double pause_at;     /* --pause-at: recording time to pause at once, s; < 0: none */
  bool loop, quiet;    /* --loop, --quiet */
} replay_options_t;

/* Exit code: 0 done (or interrupted), 1 the recording cannot be opened or
 * replayed. */
int replay_run(const replay_options_t *o);

#endif
