/* SPDX-License-Identifier: Apache-2.0 */
#include <stdlib.h>
#include <string.h>

#include "device.h"
#include "trajectory.h"

typedef struct scripted {
  trajectory_t tr;
} scripted_t;

static void scripted_read(device_t *d, double t, double pos[3], double quat[4], uint32_t *buttons) {
  scripted_t *s = d->impl;
  trajectory_eval(&s->tr, t, pos, buttons);
  quat[0] = 1;
  quat[1] = quat[2] = quat[3] = 0;
}

/* A script has no motors: the force is reported by the loop's statistics. */
static void scripted_write_force(device_t *d, const double f[3]) {
  (void)d;
  (void)f;
}

static int scripted_finished(const device_t *d, double t) {
  const scripted_t *s = d->impl;
  return t > trajectory_duration(&s->tr);
}

static void scripted_close(device_t *d) {
  scripted_t *s = d->impl;
  if (s) trajectory_free(&s->tr);
  free(s);
  d->impl = NULL;
}

static const device_ops_t SCRIPTED_OPS = {"scripted", scripted_read, scripted_write_force, scripted_finished,
                                          scripted_close};

int device_scripted_open(device_t *d, const char *trajectory_path, double max_force, verr_t *err) {
  memset(d, 0, sizeof *d);
  scripted_t *s = calloc(1, sizeof *s);
  if (!s) return verr_set(err, "out of memory");
  if (trajectory_load(trajectory_path, &s->tr, err)) {
    free(s);
    return -1;
  }
  d->ops = &SCRIPTED_OPS;
  d->max_force = max_force;
  d->impl = s;
  return 0;
}
