/* SPDX-License-Identifier: Apache-2.0 */
/* device_hd: 3D Systems / SensAble devices (Touch, Phantom) through the
 * OpenHaptics HDAPI. Compiled only when CMake finds HD/hd.h and libHD
 * (option VISCERA_DEVICE_HD); select with viscera-haptic --device hd.
 *
 * HDAPI wants position reads and force writes inside a frame of its own
 * servo scheduler (1 kHz, its thread). A scheduler callback copies the
 * newest pose out and the newest force in under a mutex held for a few
 * copies, so the viscera loop never waits for the device.
 *
 * Axes and units: HD is x right, y up, z towards the user, millimetres;
 * the scene is x right, y away from the user, z up, metres:
 * scene = (x, -z, y) / 1000, then the workspace mapping (device_frame.h). */
#include <HD/hd.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "device.h"
#include "device_frame.h"

typedef struct hd_dev {
  HHD handle;
  HDSchedulerHandle servo;
  pthread_mutex_t lock;
  device_config_t cfg;
  double pos_mm[3]; /* device axes */
  int buttons;
  double force[3]; /* device axes, N */
  int have_pose;
} hd_dev_t;

static HDCallbackCode HDCALLBACK hd_servo(void *arg) {
  hd_dev_t *h = arg;
  HDdouble p[3], f[3];
  HDint b = 0;
  hdBeginFrame(h->handle);
  hdGetDoublev(HD_CURRENT_POSITION, p);
  hdGetIntegerv(HD_CURRENT_BUTTONS, &b);
  pthread_mutex_lock(&h->lock);
  memcpy(h->pos_mm, p, sizeof h->pos_mm);
  h->buttons = b;
  h->have_pose = 1;
  memcpy(f, h->force, sizeof f);
  pthread_mutex_unlock(&h->lock);
  hdSetDoublev(HD_CURRENT_FORCE, f);
  hdEndFrame(h->handle);
  return HD_CALLBACK_CONTINUE;
}

static void hd_read(device_t *d, double t, double pos[3], double quat[4], uint32_t *buttons) {
  (void)t;
  hd_dev_t *h = d->impl;
  double p[3];
  int b;
  pthread_mutex_lock(&h->lock);
  memcpy(p, h->pos_mm, sizeof p);
  b = h->buttons;
  pthread_mutex_unlock(&h->lock);
  double s[3] = {p[0] * 1e-3, -p[2] * 1e-3, p[1] * 1e-3};
  device_to_scene(&h->cfg, s, pos);
  quat[0] = 1; /* the stylus orientation is not used by the tools yet */
  quat[1] = quat[2] = quat[3] = 0;
  *buttons = (uint32_t)((b & HD_DEVICE_BUTTON_1) ? 1u : 0u) | (uint32_t)((b & HD_DEVICE_BUTTON_2) ? 2u : 0u);
}

static void hd_write_force(device_t *d, const double f[3]) {
  hd_dev_t *h = d->impl;
  pthread_mutex_lock(&h->lock);
  h->force[0] = f[0];
  h->force[1] = f[2];
  h->force[2] = -f[1];
  pthread_mutex_unlock(&h->lock);
}

static int hd_finished(const device_t *d, double t) {
  (void)d;
  (void)t;
  return 0; /* a hand-held device runs until --duration or a signal */
}

static void hd_close(device_t *d) {
  hd_dev_t *h = d->impl;
  if (!h) return;
  double zero[3] = {0, 0, 0};
  hd_write_force(d, zero);
  hdStopScheduler();
  hdUnschedule(h->servo);
  hdDisable(HD_FORCE_OUTPUT);
  hdDisableDevice(h->handle);
  pthread_mutex_destroy(&h->lock);
  free(h);
  d->impl = NULL;
}

static const device_ops_t HD_OPS = {"hd", hd_read, hd_write_force, hd_finished, hd_close};

int device_hd_open(device_t *d, const device_config_t *cfg, verr_t *err) {
  if (cfg->index != 0)
    return verr_set(err, "device 'hd': only the default device is supported (--device-index 0); "
                         "choose it in the OpenHaptics configuration tool");
  hd_dev_t *h = calloc(1, sizeof *h);
  if (!h) return verr_set(err, "out of memory");
  h->cfg = *cfg;
  pthread_mutex_init(&h->lock, NULL);
  h->handle = hdInitDevice(HD_DEFAULT_DEVICE);
  HDErrorInfo e = hdGetError();
  if (HD_DEVICE_ERROR(e)) {
    pthread_mutex_destroy(&h->lock);
    free(h);
    return verr_set(err, "device 'hd': no OpenHaptics device found or it cannot be opened: %s",
                    hdGetErrorString(e.errorCode));
  }
  HDdouble rated = 0;
  hdGetDoublev(HD_NOMINAL_MAX_CONTINUOUS_FORCE, &rated);
  hdEnable(HD_FORCE_OUTPUT);
  h->servo = hdScheduleAsynchronous(hd_servo, h, HD_DEFAULT_SCHEDULER_PRIORITY);
  hdStartScheduler();
  e = hdGetError();
  if (HD_DEVICE_ERROR(e)) {
    hdUnschedule(h->servo);
    hdDisableDevice(h->handle);
    pthread_mutex_destroy(&h->lock);
    free(h);
    return verr_set(err, "device 'hd': cannot start the servo loop: %s", hdGetErrorString(e.errorCode));
  }
  d->ops = &HD_OPS;
  d->impl = h;
  /* Continuous rating: what the motors hold without overheating. */
  d->max_force = rated > 0 && rated < cfg->max_force ? rated : cfg->max_force;
  return 0;
}
