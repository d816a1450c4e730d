/* SPDX-License-Identifier: Apache-2.0 */
#include "input_drive.h"

#include <string.h>

#include "viscera.h"
#include "vtime.h"

static void *drive_thread(void *arg) {
  input_drive_t *d = arg;
  uint64_t period = (uint64_t)(1e9 / d->rate_hz), next = vtime_mono_ns(), seq = 0;
  for (;;) {
    vtime_sleep_until(next);
    pthread_mutex_lock(&d->lock);
    int stop = d->stop, have = d->have_pose;
    viscera_ToolCommand c;
    memset(&c, 0, sizeof c);
    c.tool_id = d->tool;
    for (int k = 0; k < 3; k++) c.position[k] = (float)d->pos[k];
    c.orientation[0] = 1; /* a mouse gives no orientation: the identity */
    c.buttons = d->buttons;
    c.max_force = d->max_force;
    pthread_mutex_unlock(&d->lock);
    if (stop) break;
    uint64_t now = vtime_mono_ns();
    if (have) {
      c.seq = ++seq;
      c.client_mono_ns = now;
      if (dds_write(d->writer, &c) == DDS_RETCODE_OK) {
        pthread_mutex_lock(&d->lock);
        d->sent++;
        pthread_mutex_unlock(&d->lock);
      }
    }
    next += period;
    if (now > next + 100000000ull) next = now; /* resynchronise after a long stall */
  }
  return NULL;
}

int input_drive_start(input_drive_t *d, vdds_t *v, uint32_t tool, double rate_hz, verr_t *err) {
  memset(d, 0, sizeof *d);
  d->tool = tool;
  d->rate_hz = rate_hz;
  d->max_force = 4;
  d->writer = vdds_writer(v, VT_TOOL_COMMAND, err);
  if (d->writer < 0) return -1;
  pthread_mutex_init(&d->lock, NULL);
  int rc = pthread_create(&d->thread, NULL, drive_thread, d);
  if (rc != 0) {
    pthread_mutex_destroy(&d->lock);
    return verr_set(err, "cannot start the 1 kHz command thread: %s", strerror(rc));
  }
  d->started = 1;
  return 0;
}

void input_drive_set(input_drive_t *d, const double pos[3], uint32_t buttons, float max_force) {
  pthread_mutex_lock(&d->lock);
  memcpy(d->pos, pos, sizeof d->pos);
  d->buttons = buttons;
  d->max_force = max_force;
  d->have_pose = 1;
  pthread_mutex_unlock(&d->lock);
}

uint64_t input_drive_sent(input_drive_t *d) {
  pthread_mutex_lock(&d->lock);
  uint64_t n = d->sent;
  pthread_mutex_unlock(&d->lock);
  return n;
}

void input_drive_stop(input_drive_t *d) {
  if (!d->started) return;
  pthread_mutex_lock(&d->lock);
  d->stop = 1;
  pthread_mutex_unlock(&d->lock);
  pthread_join(d->thread, NULL);
  pthread_mutex_destroy(&d->lock);
  d->started = 0;
}
