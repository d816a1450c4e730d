/* SPDX-License-Identifier: Apache-2.0 */
/* window: the interactive viewer (viscera-viewer --window), built only when
 * SDL2 is found (CMake option VISCERA_BUILD_WINDOW).
 *
 * One renderer, two outputs: every frame is drawn by the same OSMesa
 * renderer as the PNG frames (render.h, scene_draw.h) and shown in an SDL2
 * window, so what a trainee sees and what the offscreen viewer records are
 * the same pixels. (The renderer is not bound to a window's own OpenGL
 * context because libOSMesa exports the GL entry points itself: a second,
 * windowing GL implementation in the same process would receive some of the
 * calls. SDL presents the finished frame with its own renderer.)
 *
 * With --drive TOOL the mouse and keyboard drive that tool (input_map.h)
 * and a 1 kHz thread publishes its ToolCommand (input_drive.h); the force
 * bar shows the force the server reports for it. --script-input FILE feeds
 * timed input events through the SDL event queue (input_script.h), a demo
 * and testing aid. The event loop runs at display rate (60 Hz at most). */
#ifndef VISCERA_VIEWER_WINDOW_H
#define VISCERA_VIEWER_WINDOW_H

#include <signal.h>

#include "options.h"

/* Runs the window until it is closed, Escape, the duration or *stop.
 * Returns the process exit status (0, or 1 on a setup or runtime failure,
 * described on stderr). */
int window_main(const viewer_opts_t *o, volatile sig_atomic_t *stop);

#endif
