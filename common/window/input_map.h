/* SPDX-License-Identifier: Apache-2.0 */
/* input_map: mouse and keyboard to a tool pose, for driving a tool without a
 * haptic device (viscera-viewer --window --drive TOOL). Pure functions on
 * plain data, no SDL: the window translates its events into input_event_t,
 * tests feed them directly.
 *
 * Frames and units: scene frame, metres, z up; the view plane is the
 * camera's (camera.h): its right and up vectors span it; depth is the line
 * of sight through the tip (eye -> tip), so the tip stays under the cursor
 * while it goes deeper.
 * - Mouse motion (dx, dy pixels, x right, y down) moves the tip in the view
 *   plane by the size of a pixel at the tip's depth, so a tip that starts
 *   under the cursor stays under it.
 * - Wheel: one notch up = INPUT_WHEEL_STEP further into the scene (away from
 *   the eye), down = towards the eye. W / S held: INPUT_KEY_SPEED into /
 *   out of the scene, applied by input_map_advance with the elapsed time.
 * - Left button or space held: buttons bit 0 (grasp / cut).
 * - R: back to the home pose (above the organs' centre, clear of them).
 * The tip is clamped to the organs' bounds grown by their diagonal on every
 * side (inside the server's workspace, which is grown by at least twice
 * that), so no input can produce a command the server would reject. */
#ifndef VISCERA_VIEWER_INPUT_MAP_H
#define VISCERA_VIEWER_INPUT_MAP_H

#include <stdint.h>

#include "view/camera.h"

#define INPUT_WHEEL_STEP 0.002 /* m per wheel notch */
#define INPUT_KEY_SPEED 0.02   /* m/s while W or S is held */
/* Home: this far above the top of the organs' bounds. */
#define INPUT_HOME_CLEARANCE 0.01 /* m */

typedef enum input_kind {
  INPUT_MOTION,      /* dx, dy: relative mouse motion in pixels */
  INPUT_WHEEL,       /* n: notches, positive = away from the user (into the scene) */
  INPUT_KEY_DOWN,    /* key */
  INPUT_KEY_UP,      /* key */
  INPUT_BUTTON_DOWN, /* left mouse button */
  INPUT_BUTTON_UP
} input_kind_t;

/* Q, Tab, Escape and the digits are not mapped to the tool: they are here
 * so scripts (input_script.h) can drive the dashboard window's keys too. */
typedef enum input_key {
  INPUT_KEY_W,
  INPUT_KEY_S,
  INPUT_KEY_SPACE,
  INPUT_KEY_R,
  INPUT_KEY_Q,
  INPUT_KEY_TAB,
  INPUT_KEY_ESCAPE,
  INPUT_KEY_1, /* INPUT_KEY_1 + k - 1 is digit k, 1..9 */
  INPUT_KEY_9 = INPUT_KEY_1 + 8,
  INPUT_KEY_OTHER
} input_key_t;

typedef struct input_event {
  input_kind_t kind;
  double dx, dy; /* INPUT_MOTION */
  int n;         /* INPUT_WHEEL */
  input_key_t key;
  int at;      /* INPUT_BUTTON_*: x, y give the pointer position */
  double x, y; /* window pixels from the top-left corner */
} input_event_t;

typedef struct input_state {
  double pos[3];                  /* m, the tool tip */
  double home[3];                 /* m */
  double lo[3], hi[3];            /* clamp box */
  double right[3], up[3], fwd[3]; /* camera axes, unit */
  double eye[3];
  double px_per_rad; /* pixels per radian of view angle */
  int key_w, key_s, key_space, mouse_left;
  uint32_t buttons; /* bit 0: primary */
  uint64_t events;  /* events applied */
} input_state_t;

/* Sets up the mapping for camera c and the organs' bounds [bmin, bmax]; the
 * tip starts at home. Returns 0, or -1 when the bounds are not finite. */
int input_map_init(input_state_t *s, const camera_t *c, const double bmin[3], const double bmax[3]);

/* Applies one event. */
void input_map_apply(input_state_t *s, const input_event_t *e);

/* Moves the tip by the held W / S keys over dt seconds (dt clamped to
 * 0..0.1 s so a stalled window cannot throw the tool). */
void input_map_advance(input_state_t *s, double dt);

/* Metres one pixel spans in the view plane at the tip's depth. */
double input_map_metres_per_pixel(const input_state_t *s);

#endif
