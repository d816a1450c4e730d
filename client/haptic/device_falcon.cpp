/* SPDX-License-Identifier: Apache-2.0 */
// device_falcon: the Novint Falcon through libnifalcon (open source driver).
// Compiled only when CMake finds libnifalcon's headers and library (option
// VISCERA_DEVICE_FALCON); select with viscera-haptic --device falcon.
// C++ because libnifalcon's API is C++.
//
// libnifalcon talks to the Falcon with blocking USB transfers, one per
// runIOLoop() (about a millisecond), so a servo thread runs the I/O loop and
// exchanges the newest position, buttons and force with the viscera haptic
// thread under a mutex held for a few copies.
//
// Axes and units: libnifalcon is x right, y up, z towards the user (along
// the grip axis) with the workspace centre near z = 0.11 m
// (FALCON_CENTRE_Z), metres; the scene is x right, y away from the user,
// z up: scene = (x, 0.11 - z, y) (a rotation, no mirror), then the workspace
// mapping (device_frame.h). The Falcon is rated for about 9 N.
#include <falcon/core/FalconDevice.h>
#include <falcon/firmware/FalconFirmwareNovintSDK.h>
#include <falcon/grip/FalconGripFourButton.h>
#include <falcon/kinematic/FalconKinematicStamper.h>
#include <falcon/util/FalconFirmwareBinaryNvent.h>

#include <array>
#include <atomic>
#include <mutex>
#include <new>
#include <thread>

extern "C" {
#include "device.h"
#include "device_frame.h"
}

namespace {

constexpr double FALCON_CENTRE_Z = 0.11;
constexpr double FALCON_RATED_N = 9.0;

struct falcon_dev {
  libnifalcon::FalconDevice dev;
  device_config_t cfg;
  std::mutex lock;
  std::array<double, 3> pos{}, force{};
  unsigned buttons = 0;
  std::atomic<bool> stop{false};
  std::thread servo;
};

void servo_loop(falcon_dev *h) {
  while (!h->stop.load()) {
    std::array<double, 3> f;
    {
      std::lock_guard<std::mutex> g(h->lock);
      f = h->force;
    }
    h->dev.setForce(f);
    if (!h->dev.runIOLoop()) continue; // a missed USB transfer: try again next round
    std::array<double, 3> p = h->dev.getPosition();
    unsigned b = h->dev.getFalconGrip()->getDigitalInputs();
    std::lock_guard<std::mutex> g(h->lock);
    h->pos = p;
    h->buttons = b;
  }
  h->dev.setForce({0, 0, 0});
  h->dev.runIOLoop();
}

void falcon_read(device_t *d, double, double pos[3], double quat[4], uint32_t *buttons) {
  falcon_dev *h = static_cast<falcon_dev *>(d->impl);
  std::array<double, 3> p;
  unsigned b;
  {
    std::lock_guard<std::mutex> g(h->lock);
    p = h->pos;
    b = h->buttons;
  }
  double s[3] = {p[0], FALCON_CENTRE_Z - p[2], p[1]};
  device_to_scene(&h->cfg, s, pos);
  quat[0] = 1;
  quat[1] = quat[2] = quat[3] = 0;
  // The centre button (bit 0 in libnifalcon's four-button grip) is the primary.
  *buttons = (b & libnifalcon::FalconGripFourButton::CENTER_BUTTON) ? 1u : 0u;
  if (b & libnifalcon::FalconGripFourButton::PLUS_BUTTON) *buttons |= 2u;
}

void falcon_write_force(device_t *d, const double f[3]) {
  falcon_dev *h = static_cast<falcon_dev *>(d->impl);
  std::lock_guard<std::mutex> g(h->lock);
  h->force = {f[0], f[2], -f[1]};
}

int falcon_finished(const device_t *, double) { return 0; }

void falcon_close(device_t *d) {
  falcon_dev *h = static_cast<falcon_dev *>(d->impl);
  if (!h) return;
  h->stop.store(true);
  if (h->servo.joinable()) h->servo.join();
  h->dev.close();
  delete h;
  d->impl = nullptr;
}

const device_ops_t FALCON_OPS = {"falcon", falcon_read, falcon_write_force, falcon_finished, falcon_close};

} // namespace

extern "C" int device_falcon_open(device_t *d, const device_config_t *cfg, verr_t *err) {
  falcon_dev *h = new (std::nothrow) falcon_dev;
  if (!h) return verr_set(err, "out of memory");
  h->cfg = *cfg;
  h->dev.setFalconFirmware<libnifalcon::FalconFirmwareNovintSDK>();
  h->dev.setFalconKinematic<libnifalcon::FalconKinematicStamper>();
  h->dev.setFalconGrip<libnifalcon::FalconGripFourButton>();
  unsigned int count = 0;
  h->dev.getDeviceCount(count);
  if (count == 0) {
    delete h;
    return verr_set(err, "device 'falcon': no Falcon found (is it plugged in and powered, and may this user "
                         "access its USB device?)");
  }
  if (static_cast<unsigned>(cfg->index) >= count) {
    delete h;
    return verr_set(err, "device 'falcon': --device-index %d but only %u Falcon(s) found", cfg->index, count);
  }
  if (!h->dev.open(static_cast<unsigned>(cfg->index))) {
    delete h;
    return verr_set(err, "device 'falcon': cannot open Falcon %d (libnifalcon error %d)", cfg->index,
                    static_cast<int>(h->dev.getErrorCode()));
  }
  // A Falcon powers up without firmware; libnifalcon ships the Novint image.
  for (int tries = 0; !h->dev.isFirmwareLoaded() && tries < 10; tries++)
    h->dev.getFalconFirmware()->loadFirmware(true, libnifalcon::NOVINT_FALCON_NVENT_FIRMWARE_SIZE,
                                             const_cast<uint8_t *>(libnifalcon::NOVINT_FALCON_NVENT_FIRMWARE));
  if (!h->dev.isFirmwareLoaded()) {
    h->dev.close();
    delete h;
    return verr_set(err, "device 'falcon': cannot load the Falcon's firmware");
  }
  h->servo = std::thread(servo_loop, h);
  d->ops = &FALCON_OPS;
  d->impl = h;
  d->max_force = cfg->max_force < FALCON_RATED_N ? cfg->max_force : FALCON_RATED_N;
  return 0;
}
