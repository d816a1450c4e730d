/* SPDX-License-Identifier: Apache-2.0 */
/* device: the haptic device interface the 1 kHz loop drives.
 *
 * Contract (every implementation):
 * - read() returns the tool tip in the SCENE frame: metres, z up, the same
 *   frame as the scene file and ToolCommand. A real device converts its own
 *   axes and units (device_to_scene, device_frame.h) and applies the workspace
 *   mapping of device_config_t: scene = offset + scale * device.
 * - write_force() receives the force to render in the scene frame, newtons,
 *   already clamped to max_force; a real device rotates it back to its axes
 *   (device_force_to_device) and commands it. Forces are not scaled: with a
 *   workspace scale s, a scene stiffness k is felt as k * s.
 * - buttons: bit 0 is the primary button (grasp / cut), bit 1 the next.
 * - max_force: what the loop clamps to, min(--max-force, the device's rating).
 * - close() commands zero force before releasing the device.
 * - All calls happen on the haptic thread at the loop rate; none may block
 *   for more than a few microseconds (drivers with their own servo thread
 *   exchange the latest values with it instead of waiting).
 *
 * Implementations, selected by name with device_open (viscera-haptic
 * --device NAME): "scripted" (a trajectory file; tests and demos), always
 * built; "dhd" (Force Dimension SDK), "hd" (3D Systems OpenHaptics HDAPI) and
 * "falcon" (libnifalcon), each compiled only when CMake finds its SDK
 * (options VISCERA_DEVICE_DHD, VISCERA_DEVICE_HD, VISCERA_DEVICE_FALCON).
 * Adding a device: write device_<name>.c with an open function filling a
 * device_t, add it to the table in device_registry.c under its #ifdef, and
 * a find_path/find_library block in client/haptic/CMakeLists.txt
 * (client/haptic/README.md). */
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
  /* N/m, the stiffest wall the device renders stably (its rating, or
   * --max-stiffness); 0 = no stated limit. The client renders the server's
   * contact stiffness clamped to it, so a stiff scene stays passive on a
   * soft device. */
  double max_stiffness;
  void *impl;
};

/* What every device is opened with (viscera-haptic options). */
typedef struct device_config {
  const char *trajectory; /* scripted: the trajectory file (required) */
  double max_force;       /* N: the scripted device's stated capability; for a real device an upper clamp */
  double max_stiffness;   /* N/m: the device's stiffness rating; 0 = no stated limit */
  double scale;           /* scene metres per device metre (real devices; > 0) */
  double offset[3];       /* scene position of the device's workspace centre (real devices), m */
  int index;              /* which device of that kind, 0 = the first found */
  int loop;               /* scripted: play the trajectory over and over (never finished) */
} device_config_t;

/* Defaults: max_force 4 N, max_stiffness 0 (no limit), scale 1, offset 0, index 0, no trajectory, no loop. */
void device_config_default(device_config_t *c);

/* Opens the device called `name`. Returns 0, or -1 with err naming the
 * problem: an unknown name (listing the built-in ones), a device whose SDK
 * was not found when this binary was built, no such device attached. */
int device_open(device_t *d, const char *name, const device_config_t *cfg, verr_t *err);

/* The device names this build contains, e.g. "scripted dhd". */
const char *device_names(void);

/* Scripted device playing `trajectory_path`; max_force is its stated
 * capability. loop != 0: the path starts again at its first sample each
 * time its last sample's time has passed (a trainee who keeps palpating for
 * a whole lab) and the device never reports finished; the path must then
 * last > 0 s and end where it began (within DEVICE_LOOP_GAP_M, same
 * buttons), or the tool would jump at every repeat: err says by how much. */
#define DEVICE_LOOP_GAP_M 1e-4
int device_scripted_open(device_t *d, const char *trajectory_path, double max_force, int loop, verr_t *err);

#ifdef VISCERA_DEVICE_DHD
int device_dhd_open(device_t *d, const device_config_t *cfg, verr_t *err);
#endif
#ifdef VISCERA_DEVICE_HD
int device_hd_open(device_t *d, const device_config_t *cfg, verr_t *err);
#endif
#ifdef VISCERA_DEVICE_FALCON
int device_falcon_open(device_t *d, const device_config_t *cfg, verr_t *err);
#endif

#endif
