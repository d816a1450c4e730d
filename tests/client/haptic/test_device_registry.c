/* SPDX-License-Identifier: Apache-2.0 */
/* Device selection by name (device_registry): the scripted device opens
 * through it, SDK devices that are not in this build say so and name their
 * CMake option, unknown names list what is there; the workspace mapping of
 * real devices. */
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "contact_model.h"
#include "device.h"
#include "device_frame.h"

static void expect_error(const char *name, const device_config_t *cfg, const char *text) {
  device_t d;
  verr_t err;
  int rc = device_open(&d, name, cfg, &err);
  CHECK(rc == -1);
  if (rc == -1 && !strstr(err.msg, text)) {
    fprintf(stderr, "device '%s': got '%s', expected '%s'\n", name, err.msg, text);
    CHECK(0);
  }
}

int main(void) {
  device_config_t cfg;
  device_config_default(&cfg);
  CHECK(cfg.max_force == 4 && cfg.scale == 1 && cfg.index == 0);
  CHECK(strncmp(device_names(), "scripted", 8) == 0);

  /* Scripted through the registry. */
  char path[128];
  snprintf(path, sizeof path, "/tmp/viscera_test_%d_dev.traj", (int)getpid());
  FILE *f = fopen(path, "w");
  fputs("0 0 0 0.05\n1 0 0 0.03 1\n", f);
  fclose(f);
  expect_error("scripted", &cfg, "needs a trajectory file");
  cfg.trajectory = path;
  cfg.max_force = 2.5;
  device_t d;
  verr_t err;
  CHECK(device_open(&d, "scripted", &cfg, &err) == 0);
  CHECK(strcmp(d.ops->name, "scripted") == 0 && d.max_force == 2.5);
  double pos[3], q[4];
  uint32_t b = 0;
  d.ops->read(&d, 1.0, pos, q, &b);
  CHECK_NEAR(pos[2], 0.03, 1e-12);
  CHECK(b == 1 && q[0] == 1);
  CHECK(d.max_stiffness == 0); /* no stated limit by default */
  d.ops->close(&d);
  /* Device capability data: a stiffness rating clamps what is rendered. */
  cfg.max_stiffness = 500;
  CHECK(device_open(&d, "scripted", &cfg, &err) == 0);
  CHECK(d.max_stiffness == 500);
  contact_model_t m = {.in_contact = 1, .proxy = {0, 0, 0}, .normal = {0, 0, 1}};
  m.stiffness = contact_model_device_stiffness(800, d.max_stiffness);
  CHECK(m.stiffness == 500);
  double x[3] = {0, 0, -0.002}, fv[3];
  CHECK_NEAR(contact_model_force(&m, x, NULL, 4, fv), 1.0, 1e-12); /* 500 N/m x 2 mm, not 1.6 N */
  CHECK(contact_model_device_stiffness(300, 500) == 300);
  CHECK(contact_model_device_stiffness(800, 0) == 800);
  d.ops->close(&d);
  cfg.max_stiffness = -1;
  expect_error("scripted", &cfg, "max_stiffness must be");
  cfg.max_stiffness = 0;
  unlink(path);
  cfg.max_force = 0;
  expect_error("scripted", &cfg, "max_force must be > 0");
  cfg.max_force = 4;

  /* --loop: the path starts again after its last sample and never
   * finishes; a path that does not end where it began is refused. */
  f = fopen(path, "w");
  fputs("0 0 0 0.05\n1 0 0 0.03 1\n2 0 0 0.05\n", f);
  fclose(f);
  cfg.trajectory = path;
  CHECK(device_open(&d, "scripted", &cfg, &err) == 0); /* once */
  CHECK(d.ops->finished(&d, 2.5));
  d.ops->read(&d, 2.5, pos, q, &b);
  CHECK_NEAR(pos[2], 0.05, 1e-12); /* held at the last sample */
  d.ops->close(&d);
  cfg.loop = 1;
  CHECK(device_open(&d, "scripted", &cfg, &err) == 0);
  CHECK(!d.ops->finished(&d, 2.5) && !d.ops->finished(&d, 1e6));
  d.ops->read(&d, 2.5, pos, q, &b);
  CHECK_NEAR(pos[2], 0.04, 1e-12); /* half-way down again */
  CHECK(b == 0);
  d.ops->read(&d, 5.0, pos, q, &b);
  CHECK_NEAR(pos[2], 0.03, 1e-12); /* the third press, button held */
  CHECK(b == 1);
  d.ops->close(&d);
  f = fopen(path, "w");
  fputs("0 0 0 0.05\n1 0 0 0.03\n", f);
  fclose(f);
  expect_error("scripted", &cfg, "they are 20.0 mm apart");
  f = fopen(path, "w");
  fputs("0 0 0 0.05 1\n1 0 0 0.03\n2 0 0 0.05\n", f);
  fclose(f);
  expect_error("scripted", &cfg, "same buttons at the last sample as at the first (1, 0)");
  f = fopen(path, "w");
  fputs("0 0 0 0.05\n", f);
  fclose(f);
  expect_error("scripted", &cfg, "needs a path that lasts");
  cfg.loop = 0;
  unlink(path);

  expect_error("phantom", &cfg, "unknown device 'phantom' (this build has: scripted");
  /* Each SDK device: absent from this build -> says why; present -> with
   * no hardware attached its open fails naming the device. */
  static const struct {
    const char *name, *option;
    int built;
  } SDK[] = {
#ifdef VISCERA_DEVICE_DHD
      {"dhd", "VISCERA_DEVICE_DHD", 1},
#else
      {"dhd", "VISCERA_DEVICE_DHD", 0},
#endif
#ifdef VISCERA_DEVICE_HD
      {"hd", "VISCERA_DEVICE_HD", 1},
#else
      {"hd", "VISCERA_DEVICE_HD", 0},
#endif
#ifdef VISCERA_DEVICE_FALCON
      {"falcon", "VISCERA_DEVICE_FALCON", 1},
#else
      {"falcon", "VISCERA_DEVICE_FALCON", 0},
#endif
  };
  for (size_t i = 0; i < sizeof SDK / sizeof SDK[0]; i++) {
    if (SDK[i].built) {
      CHECK(strstr(device_names(), SDK[i].name) != NULL);
      continue; /* opening would grab real hardware if it is attached */
    }
    CHECK(strstr(device_names(), SDK[i].name) == NULL);
    expect_error(SDK[i].name, &cfg, "is not in this build");
    expect_error(SDK[i].name, &cfg, SDK[i].option);
  }

  /* Workspace mapping: scene = offset + scale * device. */
  cfg.scale = 0.5;
  cfg.offset[0] = 0.01;
  cfg.offset[1] = -0.02;
  cfg.offset[2] = 0.05;
  double p[3] = {0.1, 0.2, -0.04}, s[3];
  device_to_scene(&cfg, p, s);
  CHECK_NEAR(s[0], 0.06, 1e-15);
  CHECK_NEAR(s[1], 0.08, 1e-15);
  CHECK_NEAR(s[2], 0.03, 1e-15);
  return check_report("test_devices");
}
