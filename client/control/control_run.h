/* SPDX-License-Identifier: Apache-2.0 */
/* control_run: viscera-control once its command is parsed: wait for the
 * seat's server, send the SessionControl until the server answers, and say
 * whether it was applied or refused. */
#ifndef VISCERA_CONTROL_RUN_H
#define VISCERA_CONTROL_RUN_H

#include "viscera.h"

typedef struct control_options {
  int domain;
  const char *partition;      /* NULL: the default */
  double wait_s;              /* --wait S */
  int has_text;               /* --text given (not with the verbs that put a station in the text) */
  viscera_SessionControl cmd; /* the command to send */
} control_options_t;

/* Exit code: 0 applied, 1 refused or no answer, 2 DDS error. */
int control_run(const control_options_t *o);

#endif
