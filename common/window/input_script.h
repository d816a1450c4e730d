/* SPDX-License-Identifier: Apache-2.0 */
/* input_script: a file of timed input events, for demos and tests of the
 * window viewer's driving mode (viscera-viewer --window --drive N
 * --script-input FILE) and of the dashboard window (viscera-dashboard
 * --window --script-input FILE). The window turns each event into the SDL event a
 * user would have produced and pushes it into its own event queue when due,
 * so a script exercises the same path as a mouse and keyboard.
 *
 * Format, one event per line, '#' starts a comment, blank lines ignored:
 *   T motion DX DY     relative mouse motion, pixels (x right, y down)
 *   T wheel N          wheel notches, positive = into the scene
 *   T key_down K       K one of w s r space q tab escape 1..9 (held keys
 *   T key_up K         repeat nothing)
 *   T button_down [X Y]  left mouse button, optionally at window pixel (X, Y)
 *   T button_up [X Y]    (0..10000; the dashboard's clicks need the place)
 * T: seconds since the camera was fixed (viewer: first drawable frame;
 * dashboard: the window opened), not
 * decreasing. Values are bounded (|DX|, |DY| <= 10000, |N| <= 1000, T <= 1e6);
 * anything else is refused naming file and line. Without --duration the
 * window closes SCRIPT_TAIL_S (1 s) after the last event. */
#ifndef VISCERA_VIEWER_INPUT_SCRIPT_H
#define VISCERA_VIEWER_INPUT_SCRIPT_H

#include <stddef.h>

#include "window/input_map.h"
#include "verr.h"

typedef struct input_script_event {
  double t;
  input_event_t ev;
} input_script_event_t;

typedef struct input_script {
  input_script_event_t *ev;
  size_t n, next; /* next: first event not yet due */
} input_script_t;

int input_script_load(const char *path, input_script_t *s, verr_t *err);
void input_script_free(input_script_t *s);

/* The next event due at or before t (seconds), or NULL. */
const input_script_event_t *input_script_due(input_script_t *s, double t);
/* Time of the last event (0 for an empty script). */
double input_script_duration(const input_script_t *s);

#endif
