/* SPDX-License-Identifier: Apache-2.0 */
/* Haptic client pieces: trajectory files (good and bad) and the local
 * contact model it renders at 1 kHz. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "contact_model.h"
#include "trajectory.h"
#include "test_tmpfile.h"

int main(void) {
  trajectory_t tr;
  verr_t err;
  const char *p = test_write_tmp("ok.traj", "# t x y z buttons\n0 0 0 1\n\n1.0 0 0 0  # down\n2 1 0 0 1\n");
  CHECK(trajectory_load(p, &tr, &err) == 0);
  CHECK(tr.n == 3);
  double pos[3];
  uint32_t b;
  trajectory_eval(&tr, 0.5, pos, &b);
  CHECK_NEAR(pos[2], 0.5, 1e-12);
  trajectory_eval(&tr, 1.5, pos, &b);
  CHECK_NEAR(pos[0], 0.5, 1e-12);
  trajectory_eval(&tr, 9, pos, &b);
  CHECK(b == 1 && pos[0] == 1);
  trajectory_eval(&tr, -1, pos, &b);
  CHECK(pos[2] == 1);
  CHECK_NEAR(trajectory_duration(&tr), 2, 0);
  trajectory_free(&tr);
  remove(p);

  struct {
    const char *text, *needle;
  } bad[] = {{"0 0 0 1\n0.5 0 nan 0\n", ":2: field 'y'"},
             {"0 0 0 1\n0 1 1 1\n", ":2: field 't'"},
             {"0 0 0\n", ":1: field 'z'"},
             {"0 0 0 0 x\n", ":1: field 'buttons'"},
             {"# nothing\n", "no samples"}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    p = test_write_tmp("bad.traj", bad[i].text);
    CHECK(trajectory_load(p, &tr, &err) == -1);
    CHECK(strstr(err.msg, bad[i].needle) != NULL);
    CHECK(strstr(err.msg, "bad.traj") != NULL);
    remove(p);
  }
  CHECK(trajectory_load("/nonexistent/x.traj", &tr, &err) == -1);
  CHECK(strstr(err.msg, "/nonexistent/x.traj") != NULL);

  /* Local model: force grows with depth below the plane, zero above, clamped. */
  contact_model_t m = {.in_contact = 1, .proxy = {0, 0, 0}, .normal = {0, 0, 1}, .stiffness = 500};
  double f[3];
  CHECK_NEAR(contact_model_force(&m, (double[]){0, 0, -0.002}, NULL, 4, f), 1.0, 1e-12);
  CHECK_NEAR(f[2], 1.0, 1e-12);
  CHECK(contact_model_force(&m, (double[]){0, 0, 0.001}, NULL, 4, f) == 0);
  CHECK_NEAR(contact_model_force(&m, (double[]){0.3, 0, -0.1}, NULL, 4, f), 4, 1e-12);
  /* Damping resists motion into the wall, eases motion out, never pulls. */
  m.damping = 2;
  CHECK_NEAR(contact_model_force(&m, (double[]){0, 0, -0.002}, (double[]){0, 0, -0.1}, 4, f), 1.2, 1e-12);
  CHECK_NEAR(contact_model_force(&m, (double[]){0, 0, -0.002}, (double[]){0, 0, 0.1}, 4, f), 0.8, 1e-12);
  CHECK(contact_model_force(&m, (double[]){0, 0, -0.002}, (double[]){0, 0, 5}, 4, f) == 0);
  m.in_contact = 0;
  CHECK(contact_model_force(&m, (double[]){0, 0, -0.002}, NULL, 4, f) == 0);
  return check_report("test_haptic_client");
}
