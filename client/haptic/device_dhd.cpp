/* SPDX-License-Identifier: Apache-2.0 */
// device_dhd: Force Dimension devices (omega, delta, sigma, Novint Falcon
// with the Force Dimension driver) through the DHD SDK. Compiled only when
// CMake finds dhdc.h and libdhd (option VISCERA_DEVICE_DHD); select with
// viscera-haptic --device dhd. C++ because dhdc.h declares default
// arguments; the rest of the client stays C (device.h is extern "C" here).
//
// DHD calls are fast USB/driver calls (tens of microseconds), so they run
// directly on the viscera haptic thread, one position read and one force
// write per tick, as the SDK's own examples do.
//
// Axes and units: DHD is x towards the user, y right, z up, metres, origin
// at the workspace centre; the scene is x right, y away from the user, z up:
// scene = (y, -x, z), then the workspace mapping (device_frame.h).
#include <dhdc.h>

#include <cstdlib>
#include <cstring>

extern "C" {
#include "device.h"
#include "device_frame.h"
}

namespace {

struct dhd_dev {
  char id;
  device_config_t cfg;
};

void dhd_read(device_t *d, double, double pos[3], double quat[4], uint32_t *buttons) {
  dhd_dev *h = static_cast<dhd_dev *>(d->impl);
  double x = 0, y = 0, z = 0;
  if (dhdGetPosition(&x, &y, &z, h->id) >= 0) {
    double s[3] = {y, -x, z};
    device_to_scene(&h->cfg, s, pos);
  }
  quat[0] = 1; // orientation is not used by the tools yet
  quat[1] = quat[2] = quat[3] = 0;
  int mask = dhdGetButtonMask(h->id);
  *buttons = mask > 0 ? static_cast<uint32_t>(mask) & 3u : 0u;
}

void dhd_write_force(device_t *d, const double f[3]) {
  dhd_dev *h = static_cast<dhd_dev *>(d->impl);
  dhdSetForce(-f[1], f[0], f[2], h->id);
}

int dhd_finished(const device_t *, double) { return 0; }

void dhd_close(device_t *d) {
  dhd_dev *h = static_cast<dhd_dev *>(d->impl);
  if (!h) return;
  dhdSetForce(0, 0, 0, h->id);
  dhdEnableForce(DHD_OFF, h->id);
  dhdClose(h->id);
  std::free(h);
  d->impl = nullptr;
}

const device_ops_t DHD_OPS = {"dhd", dhd_read, dhd_write_force, dhd_finished, dhd_close};

} // namespace

extern "C" int device_dhd_open(device_t *d, const device_config_t *cfg, verr_t *err) {
  int count = dhdGetDeviceCount();
  if (count <= 0) return verr_set(err, "device 'dhd': no Force Dimension device found");
  if (cfg->index >= count)
    return verr_set(err, "device 'dhd': --device-index %d but only %d device(s) found", cfg->index, count);
  int id = dhdOpenID(static_cast<char>(cfg->index));
  if (id < 0) return verr_set(err, "device 'dhd': cannot open device %d: %s", cfg->index, dhdErrorGetLastStr());
  dhd_dev *h = static_cast<dhd_dev *>(std::calloc(1, sizeof *h));
  if (!h) {
    dhdClose(static_cast<char>(id));
    return verr_set(err, "out of memory");
  }
  h->id = static_cast<char>(id);
  h->cfg = *cfg;
  dhdEnableForce(DHD_ON, h->id);
  d->ops = &DHD_OPS;
  d->impl = h;
  d->max_force = cfg->max_force;
  return 0;
}
