/* SPDX-License-Identifier: Apache-2.0 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "device.h"
#include "trajectory.h"
#include "vmath.h"

typedef struct scripted {
  trajectory_t tr;
  double period; /* s: > 0 when looping (the last sample's time), else 0 */
} scripted_t;

static void scripted_read(device_t *d, double t, double pos[3], double quat[4], uint32_t *buttons) {
  scripted_t *s = d->impl;
  trajectory_eval(&s->tr, s->period > 0 ? fmod(t, s->period) : t, pos, buttons);
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
  return s->period == 0 && t > trajectory_duration(&s->tr);
}

static void scripted_close(device_t *d) {
  scripted_t *s = d->impl;
  if (s) trajectory_free(&s->tr);
  free(s);
  d->impl = NULL;
}

static const device_ops_t SCRIPTED_OPS = {"scripted", scripted_read, scripted_write_force, scripted_finished,
                                          scripted_close};

/* Why a path cannot loop, or 0 (device.h). */
static int check_loop(const trajectory_t *tr, const char *path, verr_t *err) {
  const trajectory_sample_t *a = &tr->s[0], *b = &tr->s[tr->n - 1];
  if (!(b->t > 0))
    return verr_set(err, "trajectory %s: --loop needs a path that lasts (its last sample is at t = %g s)", path, b->t);
  double gap = v3_dist(b->pos, a->pos);
  if (gap > DEVICE_LOOP_GAP_M)
    return verr_set(err,
                    "trajectory %s: --loop needs the last sample back at the first: they are %.1f mm apart "
                    "(at most %.1f mm), so the tool would jump at every repeat",
                    path, gap * 1e3, DEVICE_LOOP_GAP_M * 1e3);
  if (a->buttons != b->buttons)
    return verr_set(err, "trajectory %s: --loop needs the same buttons at the last sample as at the first (%u, %u)",
                    path, (unsigned)a->buttons, (unsigned)b->buttons);
  return 0;
}

int device_scripted_open(device_t *d, const char *trajectory_path, double max_force, int loop, verr_t *err) {
  memset(d, 0, sizeof *d);
  scripted_t *s = calloc(1, sizeof *s);
  if (!s) return verr_set(err, "out of memory");
  if (trajectory_load(trajectory_path, &s->tr, err) || (loop && check_loop(&s->tr, trajectory_path, err))) {
    trajectory_free(&s->tr);
    free(s);
    return -1;
  }
  if (loop) s->period = trajectory_duration(&s->tr);
  d->ops = &SCRIPTED_OPS;
  d->max_force = max_force;
  d->impl = s;
  return 0;
}
