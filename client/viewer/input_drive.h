/* SPDX-License-Identifier: Apache-2.0 */
/* input_drive: the 1 kHz ToolCommand publisher of the window viewer's
 * driving mode. The window's event loop runs at display rate (~60 Hz) and
 * hands the latest input pose over with input_drive_set; a separate thread
 * publishes it every millisecond on absolute sleeps, as a haptic client
 * does, so the server sees the same command stream (and liveliness) from a
 * mouse as from a device. Between display frames the pose simply repeats:
 * a mouse has no 1 kHz signal to sample.
 *
 * The writer asserts liveliness like any haptic client's (vdds.h), so
 * closing the window or killing the viewer releases the tool at once. */
#ifndef VISCERA_VIEWER_INPUT_DRIVE_H
#define VISCERA_VIEWER_INPUT_DRIVE_H

#include <pthread.h>
#include <stdint.h>

#include "dds/vdds.h"
#include "verr.h"

typedef struct input_drive {
  pthread_t thread;
  pthread_mutex_t lock;
  dds_entity_t writer;
  uint32_t tool;
  double rate_hz;
  /* Shared with the thread, under lock. */
  int have_pose, stop;
  double pos[3];
  uint32_t buttons;
  float max_force;
  uint64_t sent;
  int started;
} input_drive_t;

/* Creates the ToolCommand writer on v and starts the thread (it publishes
 * nothing until the first input_drive_set). Returns 0, or -1 with err. */
int input_drive_start(input_drive_t *d, vdds_t *v, uint32_t tool, double rate_hz, verr_t *err);
/* The pose to publish from now on; max_force: the device capability the
 * commands state (N). */
void input_drive_set(input_drive_t *d, const double pos[3], uint32_t buttons, float max_force);
/* Commands sent so far. */
uint64_t input_drive_sent(input_drive_t *d);
/* Stops and joins the thread; the writer goes with the participant. */
void input_drive_stop(input_drive_t *d);

#endif
