/* SPDX-License-Identifier: Apache-2.0 */
/* device_frame: the workspace mapping every real device applies in its
 * read(): device position (axes already turned to scene axes, metres) ->
 * scene position, scene = offset + scale * device (device_config_t in
 * device.h). Its own unit so a driver depends on it and not on the device
 * registry, which opens the drivers. */
#ifndef VISCERA_DEVICE_FRAME_H
#define VISCERA_DEVICE_FRAME_H

#include "device.h"

/* Workspace mapping for real devices: p (device axes already turned to
 * scene axes, metres) -> scene position. */
void device_to_scene(const device_config_t *c, const double p[3], double out[3]);

#endif
