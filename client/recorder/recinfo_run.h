/* SPDX-License-Identifier: Apache-2.0 */
/* recinfo_run: viscera-recinfo once its options are parsed: the session
 * metadata, the participants, one line per topic and, when asked, the
 * per-writer timestamp order. */
#ifndef VISCERA_RECINFO_RUN_H
#define VISCERA_RECINFO_RUN_H

#include <stdbool.h>

#include "recinfo_export.h"

enum { EXIT_OK = 0, EXIT_BAD_FILE = 1, EXIT_USAGE = 2, EXIT_NOT_MONOTONIC = 3 };

typedef struct recinfo_options {
  const char *path;              /* the recording */
  const char *topic;             /* --topic NAME, or NULL: every topic */
  bool check_mono;               /* --check-monotonic */
  export_format_t export_format; /* --export FORMAT, EXPORT_NONE: print the summary */
  const char *export_out;        /* the file it goes to */
  bool foxglove_scene;           /* --foxglove-scene */
  bool quiet;
} recinfo_options_t;

/* Exit code: EXIT_OK, EXIT_BAD_FILE or EXIT_NOT_MONOTONIC. */
int recinfo_run(const recinfo_options_t *o);

#endif
