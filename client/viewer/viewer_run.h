/* SPDX-License-Identifier: Apache-2.0 */
/* viewer_run: viscera-viewer once its options are parsed (options.c):
 * the window (--window), or the offscreen frames until a signal,
 * --duration or --max-frames. */
#ifndef VISCERA_VIEWER_RUN_H
#define VISCERA_VIEWER_RUN_H

#include "options.h"

/* Exit code: 0 on success or SIGINT/SIGTERM, 1 when OSMesa, DDS or output
 * setup fails. */
int viewer_run(const viewer_opts_t *o);

#endif
