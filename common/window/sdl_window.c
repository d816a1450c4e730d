/* SPDX-License-Identifier: Apache-2.0 */
#include "window/sdl_window.h"

#include <math.h>
#include <string.h>

int sdl_window_open(sdl_window_t *w, const char *title, int width, int height, int resizable, verr_t *err) {
  memset(w, 0, sizeof *w);
  /* The frame is ready-made pixels: SDL's software renderer presents it on
   * any X server (Xvfb included) without pulling a second GL into the
   * process; SDL_RENDER_DRIVER still overrides. */
  SDL_SetHint(SDL_HINT_RENDER_DRIVER, "software");
  /* Left to itself SDL backs the software window surface with an OpenGL
   * renderer; with OSMesa's GL symbols in the process that crashed inside
   * Mesa's GLX driver (seen under Xvfb). The X11 framebuffer (XShm) path
   * needs no GL. */
  SDL_SetHint(SDL_HINT_FRAMEBUFFER_ACCELERATION, "0");
  if (SDL_Init(SDL_INIT_VIDEO) != 0)
    return verr_set(err, "cannot open a display: %s (is DISPLAY set? the offscreen mode needs none)", SDL_GetError());
  w->inited = 1;
  w->window = SDL_CreateWindow(title, SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, width, height,
                               SDL_WINDOW_SHOWN | (resizable ? SDL_WINDOW_RESIZABLE : 0));
  if (w->window) w->sdl = SDL_CreateRenderer(w->window, -1, 0);
  if (!w->window || !w->sdl) return verr_set(err, "cannot create the window: %s", SDL_GetError());
  w->id = SDL_GetWindowID(w->window);
  return 0;
}

void sdl_window_close(sdl_window_t *w) {
  if (w->tex) SDL_DestroyTexture(w->tex);
  if (w->sdl) SDL_DestroyRenderer(w->sdl);
  if (w->window) SDL_DestroyWindow(w->window);
  if (w->inited) SDL_Quit();
  memset(w, 0, sizeof *w);
}

int sdl_window_present(sdl_window_t *w, Uint32 format, const void *pixels, int width, int height, int pitch,
                       verr_t *err) {
  if (!w->tex || w->tex_w != width || w->tex_h != height || w->tex_format != format) {
    if (w->tex) SDL_DestroyTexture(w->tex);
    w->tex = SDL_CreateTexture(w->sdl, format, SDL_TEXTUREACCESS_STREAMING, width, height);
    if (!w->tex) return verr_set(err, "cannot create a %dx%d texture: %s", width, height, SDL_GetError());
    w->tex_w = width, w->tex_h = height, w->tex_format = format;
  }
  if (SDL_UpdateTexture(w->tex, NULL, pixels, pitch) != 0 || SDL_RenderClear(w->sdl) != 0 ||
      SDL_RenderCopy(w->sdl, w->tex, NULL, NULL) != 0)
    return verr_set(err, "%s", SDL_GetError());
  SDL_RenderPresent(w->sdl);
  return 0;
}

int sdl_window_read_back(sdl_window_t *w, Uint32 format, void *pixels, int pitch, verr_t *err) {
  if (SDL_RenderReadPixels(w->sdl, NULL, format, pixels, pitch) != 0)
    return verr_set(err, "window read-back: %s", SDL_GetError());
  return 0;
}

SDL_Keycode sdl_window_key(input_key_t k) {
  if (k >= INPUT_KEY_1 && k <= INPUT_KEY_9) return SDLK_1 + (SDL_Keycode)(k - INPUT_KEY_1);
  switch (k) {
  case INPUT_KEY_W:
    return SDLK_w;
  case INPUT_KEY_S:
    return SDLK_s;
  case INPUT_KEY_R:
    return SDLK_r;
  case INPUT_KEY_Q:
    return SDLK_q;
  case INPUT_KEY_SPACE:
    return SDLK_SPACE;
  case INPUT_KEY_TAB:
    return SDLK_TAB;
  case INPUT_KEY_ESCAPE:
    return SDLK_ESCAPE;
  default:
    return SDLK_UNKNOWN;
  }
}

void sdl_window_push_input(const sdl_window_t *w, const input_event_t *e) {
  SDL_Event ev;
  memset(&ev, 0, sizeof ev);
  switch (e->kind) {
  case INPUT_MOTION:
    ev.type = SDL_MOUSEMOTION;
    ev.motion.windowID = w->id;
    ev.motion.xrel = (Sint32)lround(e->dx);
    ev.motion.yrel = (Sint32)lround(e->dy);
    break;
  case INPUT_WHEEL:
    ev.type = SDL_MOUSEWHEEL;
    ev.wheel.windowID = w->id;
    ev.wheel.y = e->n;
    ev.wheel.direction = SDL_MOUSEWHEEL_NORMAL;
    break;
  case INPUT_KEY_DOWN:
  case INPUT_KEY_UP:
    ev.type = e->kind == INPUT_KEY_DOWN ? SDL_KEYDOWN : SDL_KEYUP;
    ev.key.windowID = w->id;
    ev.key.state = e->kind == INPUT_KEY_DOWN ? SDL_PRESSED : SDL_RELEASED;
    ev.key.keysym.sym = sdl_window_key(e->key);
    break;
  case INPUT_BUTTON_DOWN:
  case INPUT_BUTTON_UP:
    ev.type = e->kind == INPUT_BUTTON_DOWN ? SDL_MOUSEBUTTONDOWN : SDL_MOUSEBUTTONUP;
    ev.button.windowID = w->id;
    ev.button.button = SDL_BUTTON_LEFT;
    ev.button.state = e->kind == INPUT_BUTTON_DOWN ? SDL_PRESSED : SDL_RELEASED;
    ev.button.clicks = 1;
    if (e->at) ev.button.x = (Sint32)lround(e->x), ev.button.y = (Sint32)lround(e->y);
    break;
  }
  SDL_PushEvent(&ev);
}
