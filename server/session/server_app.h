/* SPDX-License-Identifier: Apache-2.0 */
/* server_app: what viscera-server does once its command line is parsed
 * (session/main.c): load the scene, then either check it (--check) or run
 * the session until a signal or --duration, and print the summary. */
#ifndef VISCERA_SESSION_SERVER_APP_H
#define VISCERA_SESSION_SERVER_APP_H

#include "session/server.h"

typedef struct server_app_options {
  const char *scene_path; /* --scene FILE */
  int check_only;         /* --check */
  server_opts_t opts;     /* everything server_run takes */
} server_app_options_t;

/* Returns the exit code: 0 done, 1 scene or runtime error. */
int server_app_run(const server_app_options_t *o);

#endif
