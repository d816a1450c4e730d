/* SPDX-License-Identifier: Apache-2.0 */
/* viscera-viewer: offscreen viewer of a running scene (see options.c or
 * --help for the command line).
 *
 * One thread: poll DDS (non-blocking) every POLL_NS, and when a frame is due
 * (every --interval-ms of wall time, or on SIGUSR1) draw the latest state and
 * write a PNG plus a frames.csv row. Polling at this pace instead of waking
 * on every sample keeps a 1 kHz ToolCommand stream from costing a wakeup per
 * sample; the readers keep the latest sample per instance, so nothing drawn
 * is lost. */
#include <stdio.h>

#include "cli.h"
#include "dds/vdds_ident.h"
#include "options.h"
#include "viewer_run.h"

int main(int argc, char **argv) {
  vdds_set_role("viewer"); /* announced in the participant USER_DATA */
  viewer_opts_t o;
  int rc = options_parse(&o, argc, argv);
  if (rc != CLI_RUN) return rc;
  return viewer_run(&o);
}
