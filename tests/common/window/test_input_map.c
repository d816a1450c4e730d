/* SPDX-License-Identifier: Apache-2.0 */
/* Interactive driving without a display: the mouse/keyboard -> tool pose
 * mapping (input_map) against the camera it is defined by, and the input
 * script reader (good and bad files). */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "view/camera.h"
#include "check.h"
#include "window/input_map.h"
#include "window/input_script.h"
#include "test_tmpfile.h"

static double dist_to_eye(const input_state_t *s) {
  double d = 0;
  for (int k = 0; k < 3; k++) d += (s->pos[k] - s->eye[k]) * (s->pos[k] - s->eye[k]);
  return sqrt(d);
}

static input_event_t ev(input_kind_t kind) {
  input_event_t e;
  memset(&e, 0, sizeof e);
  e.kind = kind;
  return e;
}

static input_event_t key(input_kind_t kind, input_key_t k) {
  input_event_t e = ev(kind);
  e.key = k;
  return e;
}

static void test_mapping(void) {
  /* A kidney-sized box, framed as the viewer frames it. */
  double bmin[3] = {-0.05, -0.03, 0.0}, bmax[3] = {0.05, 0.03, 0.04};
  camera_t cam;
  CHECK(camera_frame(&cam, bmin, bmax, 640, 480) == 0);
  input_state_t s;
  CHECK(input_map_init(&s, &cam, bmin, bmax) == 0);
  /* Home: above the centre of the top, inside the clamp box. */
  CHECK_NEAR(s.pos[0], 0, 1e-12);
  CHECK_NEAR(s.pos[1], 0, 1e-12);
  CHECK_NEAR(s.pos[2], 0.04 + INPUT_HOME_CLEARANCE, 1e-12);
  CHECK(s.buttons == 0);

  /* Motion: the tip moves with the cursor, pixel for pixel, on screen. */
  double px0, py0, px1, py1;
  CHECK(camera_project(&cam, s.pos, &px0, &py0));
  input_event_t m = ev(INPUT_MOTION);
  m.dx = 30;
  m.dy = -20;
  input_map_apply(&s, &m);
  CHECK(camera_project(&cam, s.pos, &px1, &py1));
  CHECK_NEAR(px1 - px0, 30, 0.05);
  CHECK_NEAR(py1 - py0, -20, 0.05);
  /* ... and stays at the same depth. */
  double d0 = dist_to_eye(&s);

  /* Wheel: one notch into the scene = INPUT_WHEEL_STEP further from the eye
   * along the line of sight, same screen position. */
  input_event_t wh = ev(INPUT_WHEEL);
  wh.n = 1;
  input_map_apply(&s, &wh);
  CHECK(camera_project(&cam, s.pos, &px0, &py0));
  CHECK_NEAR(px0, px1, 0.05);
  CHECK_NEAR(py0, py1, 0.05);
  CHECK_NEAR(dist_to_eye(&s), d0 + INPUT_WHEEL_STEP, 1e-9);
  wh.n = -1;
  input_map_apply(&s, &wh);
  CHECK_NEAR(dist_to_eye(&s), d0, 1e-9);

  /* W held for 0.5 s: INPUT_KEY_SPEED * 0.5 into the scene; S back out. */
  double before[3];
  memcpy(before, s.pos, sizeof before);
  d0 = dist_to_eye(&s);
  CHECK(camera_project(&cam, s.pos, &px0, &py0));
  input_event_t kd = key(INPUT_KEY_DOWN, INPUT_KEY_W), ku = key(INPUT_KEY_UP, INPUT_KEY_W);
  input_map_apply(&s, &kd);
  for (int i = 0; i < 50; i++) input_map_advance(&s, 0.01);
  input_map_apply(&s, &ku);
  input_map_advance(&s, 0.01); /* released: no more motion */
  double moved = 0;
  for (int k = 0; k < 3; k++) moved += (s.pos[k] - before[k]) * (s.pos[k] - before[k]);
  CHECK_NEAR(sqrt(moved), INPUT_KEY_SPEED * 0.5, 1e-9);
  CHECK_NEAR(dist_to_eye(&s), d0 + INPUT_KEY_SPEED * 0.5, 1e-9);
  CHECK(camera_project(&cam, s.pos, &px1, &py1));
  CHECK_NEAR(px1, px0, 0.05);
  CHECK_NEAR(py1, py0, 0.05);
  /* A stall of 5 s moves no more than 0.1 s worth. */
  kd.key = INPUT_KEY_S;
  input_map_apply(&s, &kd);
  input_map_advance(&s, 5.0);
  input_map_advance(&s, NAN);
  ku.key = INPUT_KEY_S;
  input_map_apply(&s, &ku);
  CHECK_NEAR(dist_to_eye(&s), d0 + INPUT_KEY_SPEED * 0.4, 1e-9);

  /* Buttons: bit 0 while the left button or space is held. */
  input_event_t bd = ev(INPUT_BUTTON_DOWN), bu = ev(INPUT_BUTTON_UP);
  input_event_t sd = key(INPUT_KEY_DOWN, INPUT_KEY_SPACE), su = key(INPUT_KEY_UP, INPUT_KEY_SPACE);
  input_map_apply(&s, &bd);
  CHECK(s.buttons == 1);
  input_map_apply(&s, &sd);
  input_map_apply(&s, &bu);
  CHECK(s.buttons == 1); /* space still held */
  input_map_apply(&s, &su);
  CHECK(s.buttons == 0);

  /* Clamp: no input leaves the box the server accepts; NaN is ignored. */
  m.dx = 1e4;
  m.dy = 1e4;
  for (int i = 0; i < 100; i++) input_map_apply(&s, &m);
  for (int k = 0; k < 3; k++) CHECK(s.pos[k] >= s.lo[k] && s.pos[k] <= s.hi[k]);
  double diag = sqrt(0.1 * 0.1 + 0.06 * 0.06 + 0.04 * 0.04);
  CHECK(s.lo[0] >= bmin[0] - diag - 1e-12 && s.hi[2] <= bmax[2] + diag + 1e-12);
  double held[3];
  memcpy(held, s.pos, sizeof held);
  m.dx = NAN;
  input_map_apply(&s, &m);
  CHECK(memcmp(held, s.pos, sizeof held) == 0);

  /* R: home again. */
  input_event_t r = key(INPUT_KEY_DOWN, INPUT_KEY_R);
  input_map_apply(&s, &r);
  CHECK(memcmp(s.pos, s.home, sizeof s.pos) == 0);
  CHECK(s.events > 10);

  /* Bad bounds are refused. */
  double bad[3] = {0, NAN, 0};
  CHECK(input_map_init(&s, &cam, bad, bmax) == -1);
  CHECK(input_map_init(&s, &cam, bmax, bmin) == -1);
}

static void test_script(void) {
  input_script_t sc;
  verr_t err;
  const char *p = test_write_tmp("ok.input", "# demo\n0.5 motion 10 -4\n\n1 wheel -2   # out\n1 key_down space\n"
                                             "2 key_up space\n2.5 button_down\n3 button_up\n3 key_down r\n");
  CHECK(input_script_load(p, &sc, &err) == 0);
  CHECK(sc.n == 7);
  CHECK(sc.ev[0].ev.kind == INPUT_MOTION && sc.ev[0].ev.dx == 10 && sc.ev[0].ev.dy == -4);
  CHECK(sc.ev[1].ev.kind == INPUT_WHEEL && sc.ev[1].ev.n == -2);
  CHECK(sc.ev[2].ev.kind == INPUT_KEY_DOWN && sc.ev[2].ev.key == INPUT_KEY_SPACE);
  CHECK(sc.ev[4].ev.kind == INPUT_BUTTON_DOWN && sc.ev[5].ev.kind == INPUT_BUTTON_UP);
  CHECK(sc.ev[6].ev.key == INPUT_KEY_R);
  CHECK_NEAR(input_script_duration(&sc), 3, 0);
  /* Due events come out in order, each once. */
  CHECK(input_script_due(&sc, 0.4) == NULL);
  CHECK(input_script_due(&sc, 1.0) == &sc.ev[0]);
  CHECK(input_script_due(&sc, 1.0) == &sc.ev[1]);
  CHECK(input_script_due(&sc, 1.0) == &sc.ev[2]);
  CHECK(input_script_due(&sc, 1.0) == NULL);
  input_script_free(&sc);

  /* The dashboard window's keys and clicks at a place. */
  p = test_write_tmp("dash.input", "0 key_down 1\n0 key_up 9\n1 key_down tab\n1 key_down escape\n1 key_down q\n"
                                   "2 button_down 512 340\n2 button_up 512.5 0\n3 button_down\n");
  CHECK(input_script_load(p, &sc, &err) == 0);
  CHECK(sc.n == 8);
  if (sc.n == 8) {
    CHECK(sc.ev[0].ev.kind == INPUT_KEY_DOWN && sc.ev[0].ev.key == INPUT_KEY_1);
    CHECK(sc.ev[1].ev.kind == INPUT_KEY_UP && sc.ev[1].ev.key == INPUT_KEY_9);
    CHECK(sc.ev[2].ev.key == INPUT_KEY_TAB && sc.ev[3].ev.key == INPUT_KEY_ESCAPE && sc.ev[4].ev.key == INPUT_KEY_Q);
    CHECK(sc.ev[5].ev.kind == INPUT_BUTTON_DOWN && sc.ev[5].ev.at && sc.ev[5].ev.x == 512 && sc.ev[5].ev.y == 340);
    CHECK(sc.ev[6].ev.kind == INPUT_BUTTON_UP && sc.ev[6].ev.at && sc.ev[6].ev.x == 512.5 && sc.ev[6].ev.y == 0);
    CHECK(sc.ev[7].ev.kind == INPUT_BUTTON_DOWN && !sc.ev[7].ev.at);
  }
  input_script_free(&sc);
  /* The digits, Tab, Escape and Q do not move or press the tool. */
  double bmin[3] = {-0.05, -0.03, 0.0}, bmax[3] = {0.05, 0.03, 0.04};
  camera_t cam;
  input_state_t ks;
  CHECK(camera_frame(&cam, bmin, bmax, 640, 480) == 0);
  CHECK(input_map_init(&ks, &cam, bmin, bmax) == 0);
  double home[3] = {ks.pos[0], ks.pos[1], ks.pos[2]};
  const input_key_t other[] = {INPUT_KEY_1, INPUT_KEY_9, INPUT_KEY_TAB, INPUT_KEY_ESCAPE, INPUT_KEY_Q};
  for (size_t i = 0; i < sizeof other / sizeof other[0]; i++) {
    input_event_t e = {.kind = INPUT_KEY_DOWN, .key = other[i]};
    input_map_apply(&ks, &e);
  }
  input_map_advance(&ks, 0.1);
  CHECK(ks.pos[0] == home[0] && ks.pos[1] == home[1] && ks.pos[2] == home[2] && ks.buttons == 0);

  static const struct {
    const char *text, *expect;
  } BAD[] = {
      {"0 motion 1\n", ":1: motion takes 2 value(s), got 1"},
      {"0 motion 1 nan\n", ":1: motion: expected DX DY"},
      {"0 wheel 1.5\n", ":1: wheel: expected an integer"},
      {"0 key_down x\n", ":1: key_down: unknown key 'x'"},
      {"0 key_down 0\n", ":1: key_down: unknown key '0'"},
      {"0 key_down 12\n", ":1: key_down: unknown key '12'"},
      {"0 button_down 10 -1\n", ":1: button_down: expected X Y in window pixels"},
      {"0 button_up 10 20000\n", ":1: button_up: expected X Y in window pixels"},
      {"0 jump\n", ":1: unknown event 'jump'"},
      {"1 wheel 1\n0.5 wheel 1\n", ":2: time 0.5 is before the previous event's 1"},
      {"-1 wheel 1\n", ":1: time '-1'"},
      {"x wheel 1\n", ":1: time 'x'"},
      {"0\n", ":1: missing event"},
      {"0 button_down now\n", ":1: button_down takes 0 value(s), got 1"},
      {"0 motion 1 2 3 4\n", ":1: too many fields"},
  };
  for (size_t i = 0; i < sizeof BAD / sizeof BAD[0]; i++) {
    p = test_write_tmp("bad.input", BAD[i].text);
    int rc = input_script_load(p, &sc, &err);
    CHECK(rc == -1);
    if (rc == -1 && !strstr(err.msg, BAD[i].expect)) {
      fprintf(stderr, "case %zu: got '%s', expected '%s'\n", i, err.msg, BAD[i].expect);
      CHECK(0);
    }
  }
  CHECK(input_script_load("/nonexistent/x.input", &sc, &err) == -1 && strstr(err.msg, "cannot open"));
  unlink(p);
  unlink(test_write_tmp("ok.input", ""));
}

int main(void) {
  test_mapping();
  test_script();
  return check_report("test_input_map");
}
