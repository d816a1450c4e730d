/* SPDX-License-Identifier: Apache-2.0 */
/* device_registry: device names -> open functions. Devices whose SDK was not found at
 * configure time are still listed, so asking for one says why it is absent
 * instead of "unknown device". */
#include <string.h>

#include "device.h"

typedef struct device_entry {
  const char *name;
  const char *what;   /* for messages */
  const char *option; /* the CMake option that builds it */
  int built;
} device_entry_t;

static const device_entry_t DEVICES[] = {
    {"scripted", "scripted device (trajectory file)", "", 1},
#ifdef VISCERA_DEVICE_DHD
    {"dhd", "Force Dimension device (DHD SDK)", "VISCERA_DEVICE_DHD", 1},
#else
    {"dhd", "Force Dimension device (DHD SDK)", "VISCERA_DEVICE_DHD", 0},
#endif
#ifdef VISCERA_DEVICE_HD
    {"hd", "OpenHaptics device (HDAPI)", "VISCERA_DEVICE_HD", 1},
#else
    {"hd", "OpenHaptics device (HDAPI)", "VISCERA_DEVICE_HD", 0},
#endif
#ifdef VISCERA_DEVICE_FALCON
    {"falcon", "Novint Falcon (libnifalcon)", "VISCERA_DEVICE_FALCON", 1},
#else
    {"falcon", "Novint Falcon (libnifalcon)", "VISCERA_DEVICE_FALCON", 0},
#endif
};
#define NDEVICES (sizeof DEVICES / sizeof DEVICES[0])

void device_config_default(device_config_t *c) {
  memset(c, 0, sizeof *c);
  c->max_force = 4;
  c->max_stiffness = 0;
  c->scale = 1;
}

const char *device_names(void) {
  static char names[128];
  if (!names[0]) {
    for (size_t i = 0; i < NDEVICES; i++) {
      if (!DEVICES[i].built) continue;
      if (names[0]) strcat(names, " ");
      strcat(names, DEVICES[i].name);
    }
  }
  return names;
}

static int open_named(device_t *d, const char *name, const device_config_t *cfg, verr_t *err) {
  memset(d, 0, sizeof *d);
  const device_entry_t *e = NULL;
  for (size_t i = 0; i < NDEVICES; i++)
    if (strcmp(DEVICES[i].name, name) == 0) e = &DEVICES[i];
  if (!e) return verr_set(err, "unknown device '%s' (this build has: %s)", name, device_names());
  if (!e->built)
    return verr_set(err,
                    "device '%s' (%s) is not in this build: its SDK was not found when it was configured "
                    "(install the SDK and reconfigure; CMake option %s; this build has: %s)",
                    name, e->what, e->option, device_names());
  if (!(cfg->max_force > 0)) return verr_set(err, "device '%s': max_force must be > 0", name);
  if (strcmp(name, "scripted") == 0) {
    if (!cfg->trajectory) return verr_set(err, "device 'scripted' needs a trajectory file (--trajectory FILE)");
    return device_scripted_open(d, cfg->trajectory, cfg->max_force, cfg->loop, err);
  }
  if (!(cfg->scale > 0)) return verr_set(err, "device '%s': workspace scale must be > 0", name);
#ifdef VISCERA_DEVICE_DHD
  if (strcmp(name, "dhd") == 0) return device_dhd_open(d, cfg, err);
#endif
#ifdef VISCERA_DEVICE_HD
  if (strcmp(name, "hd") == 0) return device_hd_open(d, cfg, err);
#endif
#ifdef VISCERA_DEVICE_FALCON
  if (strcmp(name, "falcon") == 0) return device_falcon_open(d, cfg, err);
#endif
  return verr_set(err, "device '%s': no open function (build error)", name);
}

int device_open(device_t *d, const char *name, const device_config_t *cfg, verr_t *err) {
  if (!(cfg->max_stiffness >= 0) || cfg->max_stiffness > 1e6)
    return verr_set(err, "device '%s': max_stiffness must be 0 (no stated limit) or up to 1e6 N/m", name);
  int rc = open_named(d, name, cfg, err);
  /* The stiffness the device renders stably: its configured rating (no
   * driver here reads one from its SDK yet). */
  if (rc == 0) d->max_stiffness = cfg->max_stiffness;
  return rc;
}
