/* SPDX-License-Identifier: Apache-2.0 */
/* dash_window: the dashboard live in an SDL2 window (viscera-dashboard
 * --window), built only when SDL2 is (CMake VISCERA_BUILD_WINDOW).
 *
 * The window shows the grid (dash_draw.h) or one seat's focus view, drawn
 * with cairo at the window's size (it is resizable; the grid keeps its tile
 * size and is centred) and presented through the viewer's SDL window
 * (sdl_window.h), so the window and the PNG frames are the same drawing.
 * A footer line lists the keys:
 *   1-9          focus that tile's seat        click a tile  focus it
 *   Tab/Shift+Tab next / previous seat          Esc or click  back to the grid
 *   Q or closing the window                     quit
 * --script-input FILE (input_script.h: key_down 1..9 tab escape q,
 * button_down X Y) feeds the same keys and clicks through the SDL queue,
 * timed from the window's opening; the window closes 1 s after the last
 * event. Each change of view is printed on stdout ("dashboard: focus
 * lab/seat01 (key 1)", "dashboard: grid (escape)"). */
#ifndef VISCERA_DASHBOARD_DASH_WINDOW_H
#define VISCERA_DASHBOARD_DASH_WINDOW_H

#include <cairo.h>
#include <stdint.h>

#include "dash_draw.h"
#include "window/input_script.h"
#include "window/sdl_window.h"

#define DASH_WINDOW_FOOTER_H 22

typedef struct dash_window {
  sdl_window_t sw;
  cairo_surface_t *canvas; /* what the window shows, at its size */
  int w, h;
  int gx, gy;  /* where the grid was last drawn */
  int focused; /* seat index, -1 for the grid */
  input_script_t script;
  uint64_t t_open_ns;
  long shown, changes;
  double draw_s; /* summed time drawing and presenting, for the closing line */
} dash_window_t;

/* Opens a width x height window (resizable, not smaller than the focus
 * view's minimum). script_path may be NULL. 0, or -1 with err; call
 * dash_window_close whatever the result. */
int dash_window_open(dash_window_t *w, int width, int height, const char *script_path, verr_t *err);
void dash_window_close(dash_window_t *w);

/* One refresh: feeds due scripted input, handles the queued events, draws
 * the current view into the canvas and presents it. Returns 1 when the user
 * quit (or the script is over), 0 to go on, -1 with err on a failure. */
int dash_window_tick(dash_window_t *w, dash_t *d, verr_t *err);

/* Reads back what the window shows, writes it as a PNG at path and returns
 * how many pixels differ from the canvas (0: the window shows exactly the
 * drawing), or -1 with err. */
long dash_window_snapshot(dash_window_t *w, const char *path, verr_t *err);

#endif
