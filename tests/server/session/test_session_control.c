/* SPDX-License-Identifier: Apache-2.0 */
/* session_control: what an instructor command does to a seat, and what it
 * is refused for. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "session/session_control.h"

static scene_t scene; /* one organ, defaults; what RESET and SET_MATERIAL edit */

static viscera_SessionControl cmd(uint32_t station, uint64_t seq, viscera_ControlKind kind, int32_t tool, double st,
                                  double mpf, double sft) {
  viscera_SessionControl c;
  memset(&c, 0, sizeof c);
  c.source_id = station;
  c.seq = seq;
  c.kind = kind;
  c.tool_id = tool;
  c.values[0] = st;
  c.values[1] = mpf;
  c.values[2] = sft;
  return c;
}

static void test_pause_resume(void) {
  session_control_t sc;
  memset(&sc, 0, sizeof sc);
  session_tool_t tools[1];
  thr_init(&tools[0].thr, 0.5, 0.8, 1.5);
  double maxf[1] = {4};
  char text[200];
  viscera_SessionControl c = cmd(3, 10, viscera_CONTROL_PAUSE, -1, 0, 0, 0);
  CHECK(session_control_apply(&sc, &c, tools, 1, maxf, &scene, text, sizeof text) == 0);
  CHECK(sc.paused == 1);
  CHECK(strstr(text, "paused") && strstr(text, "[station 3 seq 10]"));
  c = cmd(3, 11, viscera_CONTROL_RESUME, -1, 0, 0, 0);
  CHECK(session_control_apply(&sc, &c, tools, 1, maxf, &scene, text, sizeof text) == 0);
  CHECK(sc.paused == 0);
  CHECK(sc.applied == 2 && sc.refused == 0);
  c = cmd(3, 12, (viscera_ControlKind)77, -1, 0, 0, 0);
  CHECK(session_control_apply(&sc, &c, tools, 1, maxf, &scene, text, sizeof text) == -1);
  CHECK(strstr(text, "unknown command kind") != NULL);
  CHECK(sc.paused == 0);
}

static void test_thresholds(void) {
  session_control_t sc;
  memset(&sc, 0, sizeof sc);
  session_tool_t tools[2];
  thr_init(&tools[0].thr, 0.5, 0.8, 1.5);
  thr_init(&tools[1].thr, 0, 0, 0);
  double maxf[2] = {4, 2};
  char text[200];
  /* Measures accumulated so far survive a change of levels. */
  thr_event_t ev[THR_COUNT];
  const double p0[3] = {0, 0, 0}, p1[3] = {0.01, 0, 0};
  thr_update(&tools[0].thr, 0.001, 1.0, 1, p0, ev);
  thr_update(&tools[0].thr, 0.001, 1.0, 1, p1, ev);
  double above_st = tools[0].thr.time_above[THR_ST], path = tools[0].thr.path_length;
  CHECK(above_st > 0 && path > 0.009);

  viscera_SessionControl c = cmd(1, 1, viscera_CONTROL_SET_THRESHOLDS, 0, 0.4, 0.7, 1.2);
  CHECK(session_control_apply(&sc, &c, tools, 2, maxf, &scene, text, sizeof text) == 0);
  CHECK_NEAR(tools[0].thr.level[THR_ST], 0.4, 0);
  CHECK_NEAR(tools[0].thr.level[THR_MPF], 0.7, 0);
  CHECK_NEAR(tools[0].thr.level[THR_SFT], 1.2, 0);
  CHECK_NEAR(tools[0].thr.time_above[THR_ST], above_st, 0);
  CHECK_NEAR(tools[0].thr.path_length, path, 0);
  /* The force (1 N) is above the new ST and MPF: reported again as crossings. */
  int n = thr_update(&tools[0].thr, 0.001, 1.0, 1, p1, ev);
  CHECK(n == 2);

  /* Refused, nothing changed. */
  const double bad[][3] = {{0.8, 0.5, 1.5}, {0.5, 1.6, 1.5}, {NAN, 0.8, 1.5}, {-1, 0.8, 1.5}, {0.5, 0.8, 9}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    c = cmd(1, 2 + i, viscera_CONTROL_SET_THRESHOLDS, 0, bad[i][0], bad[i][1], bad[i][2]);
    CHECK(session_control_apply(&sc, &c, tools, 2, maxf, &scene, text, sizeof text) == -1);
    CHECK(strstr(text, "refused") != NULL);
    CHECK_NEAR(tools[0].thr.level[THR_ST], 0.4, 0);
    CHECK_NEAR(tools[0].thr.level[THR_SFT], 1.2, 0);
  }
  c = cmd(1, 20, viscera_CONTROL_SET_THRESHOLDS, 2, 0.4, 0.7, 1.2); /* no tool 2 */
  CHECK(session_control_apply(&sc, &c, tools, 2, maxf, &scene, text, sizeof text) == -1);
  c = cmd(1, 21, viscera_CONTROL_SET_THRESHOLDS, -1, 0.4, 0.7, 1.2);
  CHECK(session_control_apply(&sc, &c, tools, 2, maxf, &scene, text, sizeof text) == -1);
  c = cmd(1, 22, viscera_CONTROL_SET_THRESHOLDS, 1, 0.5, 1.0, 2.5); /* tool 1 clamps at 2 N */
  CHECK(session_control_apply(&sc, &c, tools, 2, maxf, &scene, text, sizeof text) == -1);
  c = cmd(1, 23, viscera_CONTROL_SET_THRESHOLDS, 1, 0, 1.0, 0); /* only MPF set: valid */
  CHECK(session_control_apply(&sc, &c, tools, 2, maxf, &scene, text, sizeof text) == 0);
  CHECK_NEAR(tools[1].thr.level[THR_MPF], 1.0, 0);
  CHECK(sc.refused == 8 && sc.applied == 2);
}

static void test_rebuild_commands(void) {
  session_control_t sc;
  memset(&sc, 0, sizeof sc);
  session_tool_t tools[1];
  thr_init(&tools[0].thr, 0.5, 0.8, 1.5);
  double maxf[1] = {4};
  char text[300];
  memset(&scene, 0, sizeof scene);
  scene.norgans = 1;
  snprintf(scene.organs[0].name, sizeof scene.organs[0].name, "kidney");
  scene.organs[0].material = (scene_material_t){.mass = 0.15, .stiffness = 30, .damping = 0.02, .home_stiffness = 30};
  viscera_SessionControl c = cmd(1, 1, viscera_CONTROL_RESET, -1, 0, 0, 0);
  CHECK(session_control_apply(&sc, &c, tools, 1, maxf, &scene, text, sizeof text) == SESSION_CONTROL_REBUILD);
  CHECK(strstr(text, "reset") != NULL);
  /* New stiffness and mass, damping and home stiffness kept (-1). */
  c = cmd(1, 2, viscera_CONTROL_SET_MATERIAL, -1, 90, -1, -1);
  c.organ_id = 0;
  c.values[3] = 0.3;
  CHECK(session_control_apply(&sc, &c, tools, 1, maxf, &scene, text, sizeof text) == SESSION_CONTROL_REBUILD);
  CHECK_NEAR(scene.organs[0].material.stiffness, 90, 0);
  CHECK_NEAR(scene.organs[0].material.damping, 0.02, 0);
  CHECK_NEAR(scene.organs[0].material.home_stiffness, 30, 0);
  CHECK_NEAR(scene.organs[0].material.mass, 0.3, 0);
  /* Refused, material unchanged: bad organ, NaN, zero mass, absurd stiffness. */
  /* Issue 15: 1e-300 kg and 1e300 N/m passed and rolled back every contact
   * step; the scene file's ranges (scene_limits.h) now apply. */
  const double bad[][4] = {{NAN, -1, -1, -1},    {-1, -1, -1, 0},     {1e9, -1, -1, -1},   {-1, INFINITY, -1, -1},
                           {-1, -1, -1, 1e-300}, {1e300, -1, -1, -1}, {-1, -1, 1e300, -1}, {-1, 1e6, -1, -1}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    c = cmd(1, 3 + i, viscera_CONTROL_SET_MATERIAL, -1, 0, 0, 0);
    c.organ_id = 0;
    memcpy(c.values, bad[i], sizeof c.values);
    CHECK(session_control_apply(&sc, &c, tools, 1, maxf, &scene, text, sizeof text) == -1);
    CHECK_NEAR(scene.organs[0].material.stiffness, 90, 0);
    CHECK_NEAR(scene.organs[0].material.mass, 0.3, 0);
  }
  c = cmd(1, 20, viscera_CONTROL_SET_MATERIAL, -1, -1, -1, -1);
  c.organ_id = 0;
  c.values[3] = 1e-300;
  CHECK(session_control_apply(&sc, &c, tools, 1, maxf, &scene, text, sizeof text) == -1);
  CHECK(strstr(text, "organs.material.mass = 1e-300: must be >= 0.001 and <= 20 kg") != NULL);
  c = cmd(1, 21, viscera_CONTROL_SET_MATERIAL, -1, 50, -1, -1);
  c.organ_id = 1; /* no such organ */
  CHECK(session_control_apply(&sc, &c, tools, 1, maxf, &scene, text, sizeof text) == -1);
  CHECK(strstr(text, "organ id out of range") != NULL);
}

static void test_duplicates(void) {
  session_control_t sc;
  memset(&sc, 0, sizeof sc);
  viscera_SessionControl c = cmd(5, 100, viscera_CONTROL_PAUSE, -1, 0, 0, 0);
  CHECK(session_control_duplicate(&sc, &c) == 0);
  CHECK(session_control_duplicate(&sc, &c) == 1); /* resent copy */
  c.seq = 99;
  CHECK(session_control_duplicate(&sc, &c) == 1); /* older */
  c.seq = 101;
  CHECK(session_control_duplicate(&sc, &c) == 0);
  viscera_SessionControl d = cmd(6, 1, viscera_CONTROL_PAUSE, -1, 0, 0, 0); /* another station */
  CHECK(session_control_duplicate(&sc, &d) == 0);
  /* More stations than the table holds: still bounded, new ones accepted. */
  for (uint32_t s = 100; s < 100 + 3 * SESSION_CONTROL_STATIONS; s++) {
    viscera_SessionControl e = cmd(s, 1, viscera_CONTROL_PAUSE, -1, 0, 0, 0);
    CHECK(session_control_duplicate(&sc, &e) == 0);
  }
  CHECK(sc.nstations == SESSION_CONTROL_STATIONS);
  CHECK(sc.duplicates == 2);
}

int main(void) {
  test_pause_resume();
  test_thresholds();
  test_rebuild_commands();
  test_duplicates();
  return check_report("test_session_control");
}
