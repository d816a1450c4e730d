/* device: the haptic device interface the 1 kHz loop drives.
 *
 * Implementations: scripted (a trajectory file; tests and demos). Real devices
 * (OpenHaptics, Force Dimension, libnifalcon) and interactive input plug in
 * here: fill a device_t with ops, compiled only when their SDK is found.
 * All calls happen on the haptic thread; none may block for more than a few
 * microseconds. */
#ifndef VISCERA_DEVICE_H
#define VISCERA_DEVICE_H

#include <stdint.h>

#include "verr.h"

typedef struct device device_t;

typedef struct device_ops {
  const char *name;
  /* Pose at t seconds since the loop started: tip position (m) and buttons. */
  void (*read)(device_t *d, double t, double pos[3], double quat[4], uint32_t *buttons);
  /* Force to render (N, already clamped to max_force). */
  void (*write_force)(device_t *d, const double f[3]);
  /* 1 when a scripted device has played its whole script. */
  int (*finished)(const device_t *d, double t);
  void (*close)(device_t *d);
} device_ops_t;

struct device {
  const device_ops_t *ops;
  double max_force; /* N, the device's capability */
  void *impl;
};

/* Scripted device playing `trajectory_path`; max_force is its stated capability. */
int device_scripted_open(device_t *d, const char *trajectory_path, double max_force, verr_t *err);

#endif
