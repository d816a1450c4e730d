/* SPDX-License-Identifier: Apache-2.0 */
/* viscera-haptic: a haptic-device client. Runs a 1 kHz loop that reads the
 * device, publishes ToolCommand and renders force from the latest
 * ContactFeedback's local contact model, coupled to the peer station's
 * device while the tool is guided (guide_force.h). Prints rate, jitter,
 * force, latency and guiding statistics on exit.
 *
 * The command line is haptic_options.c; the run haptic_run.c, its DDS side
 * haptic_dds.c, the loop haptic_loop.c and the exit figures
 * haptic_summary.c. */
#include "cli.h"
#include "cpu_wake.h"
#include "dds/vdds.h"
#include "haptic_options.h"
#include "haptic_run.h"

int main(int argc, char **argv) {
  vdds_set_role("haptic"); /* announced in the participant USER_DATA */
  haptic_options_t o;
  int rc = haptic_options_parse(&o, argc, argv);
  if (rc != CLI_RUN) return rc;
  /* Held for the whole run, released at exit (main owns it: machine-wide). */
  cpu_wake_t wake = {.fd = -1};
  if (o.cpu_wake_us >= 0) {
    cpu_wake_hold(&wake, o.cpu_wake_us);
    cpu_wake_report(&wake, "haptic", stderr);
  }
  rc = haptic_run(&o);
  cpu_wake_release(&wake);
  return rc;
}
