/* SPDX-License-Identifier: Apache-2.0 */
/* recorder_run: viscera-recorder once its options are parsed: open the
 * session, record until a signal, --duration or a full disk, and close. */
#ifndef VISCERA_RECORDER_RUN_H
#define VISCERA_RECORDER_RUN_H

#include <stdbool.h>

#include "session.h"

typedef struct recorder_options {
  rec_session_opts_t session; /* out, force, domain, partition, scene, depth, log */
  double duration;            /* --duration S; 0: until SIGINT/SIGTERM */
  bool quiet;                 /* --quiet */
} recorder_options_t;

/* Exit code: 0 done, 1 runtime error (disk full included). */
int recorder_run(const recorder_options_t *ro);

#endif
