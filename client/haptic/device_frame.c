/* SPDX-License-Identifier: Apache-2.0 */
#include "device_frame.h"

void device_to_scene(const device_config_t *c, const double p[3], double out[3]) {
  for (int k = 0; k < 3; k++) out[k] = c->offset[k] + c->scale * p[k];
}
