/* SPDX-License-Identifier: Apache-2.0 */
/* sdl_window: an SDL2 window that shows ready-made frames, shared by the
 * window viewer (window.h) and the dashboard window (dash_window.h).
 *
 * Frames come from OSMesa or cairo as plain pixels; SDL's software renderer
 * presents them. The process must not load a second, windowing OpenGL next
 * to OSMesa (which exports the GL entry points itself), so open forces the
 * software renderer and turns off framebuffer acceleration (see the comment
 * in sdl_window.c); SDL_RENDER_DRIVER still overrides the former.
 *
 * Scripted input (input_script.h) becomes the SDL event a user would have
 * produced, pushed into the window's own queue, so a script exercises the
 * same handling as a mouse and keyboard. */
#ifndef VISCERA_VIEWER_SDL_WINDOW_H
#define VISCERA_VIEWER_SDL_WINDOW_H

#include <SDL.h>

#include "window/input_map.h"
#include "verr.h"

typedef struct sdl_window {
  SDL_Window *window;
  SDL_Renderer *sdl;
  SDL_Texture *tex;
  int tex_w, tex_h;
  Uint32 tex_format, id;
  int inited;
} sdl_window_t;

/* Initialises SDL video and opens a width x height window titled `title`
 * (resizable when asked). Returns 0, or -1 with err naming the cause (no
 * display: says that the offscreen modes need none). Call sdl_window_close
 * whatever the result. */
int sdl_window_open(sdl_window_t *w, const char *title, int width, int height, int resizable, verr_t *err);
void sdl_window_close(sdl_window_t *w);

/* Shows width x height pixels (top-down rows, `pitch` bytes apart, SDL pixel
 * format `format`: SDL_PIXELFORMAT_RGB24 for the renderer's bytes,
 * SDL_PIXELFORMAT_RGB888 for a cairo RGB24 surface), stretched to the
 * window. The texture follows the frame's size. Returns 0, or -1 with err. */
int sdl_window_present(sdl_window_t *w, Uint32 format, const void *pixels, int width, int height, int pitch,
                       verr_t *err);

/* Reads back what the window shows now (the last presented frame) in
 * `format` into pixels (window size, `pitch` bytes a row). 0, or -1 with err. */
int sdl_window_read_back(sdl_window_t *w, Uint32 format, void *pixels, int pitch, verr_t *err);

/* Pushes the SDL event a user would have produced for e into the queue. */
void sdl_window_push_input(const sdl_window_t *w, const input_event_t *e);

/* The SDL key for a mapping key (SDLK_UNKNOWN for INPUT_KEY_OTHER). */
SDL_Keycode sdl_window_key(input_key_t k);

#endif
