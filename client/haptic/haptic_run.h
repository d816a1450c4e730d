/* SPDX-License-Identifier: Apache-2.0 */
/* haptic_run: viscera-haptic once its options are parsed: open the device
 * and DDS, wait for the server's scene, run the loop, print the summary. */
#ifndef VISCERA_HAPTIC_RUN_H
#define VISCERA_HAPTIC_RUN_H

#include "haptic_options.h"

/* Returns the exit code: 0 done, 1 device, DDS, file or server error. */
int haptic_run(const haptic_options_t *o);

#endif
