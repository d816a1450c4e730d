/* SPDX-License-Identifier: Apache-2.0 */
#include "dash_window.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vtime.h"

#define SCRIPT_TAIL_S 1.0 /* as the viewer: a scripted session ends this long after its last event */

static int make_canvas(dash_window_t *w, int width, int height, verr_t *err) {
  if (w->canvas) cairo_surface_destroy(w->canvas);
  w->canvas = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height);
  if (cairo_surface_status(w->canvas) != CAIRO_STATUS_SUCCESS)
    return verr_set(err, "cannot make a %dx%d canvas", width, height);
  w->w = width, w->h = height;
  return 0;
}

int dash_window_open(dash_window_t *w, int width, int height, const char *script_path, verr_t *err) {
  memset(w, 0, sizeof *w);
  w->focused = -1;
  if (width < DASH_FOCUS_MIN_W) width = DASH_FOCUS_MIN_W;
  if (height < DASH_FOCUS_MIN_H + DASH_WINDOW_FOOTER_H) height = DASH_FOCUS_MIN_H + DASH_WINDOW_FOOTER_H;
  if (script_path && input_script_load(script_path, &w->script, err)) return -1;
  if (sdl_window_open(&w->sw, "viscera dashboard", width, height, 1, err)) return -1;
  SDL_SetWindowMinimumSize(w->sw.window, DASH_FOCUS_MIN_W, DASH_FOCUS_MIN_H + DASH_WINDOW_FOOTER_H);
  if (make_canvas(w, width, height, err)) return -1;
  w->t_open_ns = vtime_mono_ns();
  return 0;
}

void dash_window_close(dash_window_t *w) {
  if (w->canvas) cairo_surface_destroy(w->canvas);
  sdl_window_close(&w->sw);
  input_script_free(&w->script);
  memset(w, 0, sizeof *w);
}

static void set_view(dash_window_t *w, const dash_t *d, int seat, const char *why) {
  if (seat == w->focused) return;
  w->focused = seat;
  w->changes++;
  if (seat >= 0)
    printf("dashboard: focus %s (%s)\n", d->seats[seat].partition, why);
  else
    printf("dashboard: grid (%s)\n", why);
  fflush(stdout);
}

/* Handles one event; returns 1 when the user asked to quit. */
static int handle(dash_window_t *w, const dash_t *d, const SDL_Event *ev) {
  char why[32];
  switch (ev->type) {
  case SDL_QUIT:
    return 1;
  case SDL_KEYDOWN: {
    SDL_Keycode k = ev->key.keysym.sym;
    if (ev->key.repeat) return 0;
    if (k == SDLK_q) return 1;
    if (k == SDLK_ESCAPE) set_view(w, d, -1, "escape");
    if (k >= SDLK_1 && k <= SDLK_9 && k - SDLK_1 < d->nseats) {
      snprintf(why, sizeof why, "key %d", (int)(k - SDLK_1) + 1);
      set_view(w, d, (int)(k - SDLK_1), why);
    }
    if (k == SDLK_TAB) {
      int back = (ev->key.keysym.mod & KMOD_SHIFT) != 0;
      int next = w->focused < 0 ? (back ? d->nseats - 1 : 0) : (w->focused + (back ? d->nseats - 1 : 1)) % d->nseats;
      set_view(w, d, next, back ? "shift+tab" : "tab");
    }
    return 0;
  }
  case SDL_MOUSEBUTTONDOWN:
    if (ev->button.button != SDL_BUTTON_LEFT) return 0;
    if (w->focused >= 0) {
      set_view(w, d, -1, "click");
    } else {
      int i = dash_tile_at(d, w->gx, w->gy, ev->button.x, ev->button.y);
      if (i >= 0) set_view(w, d, i, "click");
    }
    return 0;
  default:
    return 0;
  }
}

static void footer(dash_window_t *w, cairo_t *cr) {
  int y = w->h - DASH_WINDOW_FOOTER_H;
  cairo_set_source_rgb(cr, 0.13, 0.13, 0.15);
  cairo_rectangle(cr, 0, y, w->w, DASH_WINDOW_FOOTER_H);
  cairo_fill(cr);
  cairo_set_source_rgb(cr, 0.75, 0.75, 0.8);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 12);
  cairo_move_to(cr, 10, y + 15);
  cairo_show_text(cr, w->focused < 0 ? "1-9 or click a tile: focus a seat    Tab: next seat    Q: quit"
                                     : "Esc or click: back to the grid    Tab / Shift+Tab: next / previous seat    "
                                       "1-9: seat    Q: quit");
}

int dash_window_tick(dash_window_t *w, dash_t *d, verr_t *err) {
  uint64_t now = vtime_mono_ns();
  double t = (double)(now - w->t_open_ns) * 1e-9;
  const input_script_event_t *se;
  while ((se = input_script_due(&w->script, t))) sdl_window_push_input(&w->sw, &se->ev);
  int quit = w->script.n && w->script.next == w->script.n && t >= input_script_duration(&w->script) + SCRIPT_TAIL_S;
  SDL_Event ev;
  while (SDL_PollEvent(&ev))
    if (handle(w, d, &ev)) quit = 1;
  int ww, wh;
  SDL_GetRendererOutputSize(w->sw.sdl, &ww, &wh);
  if ((ww != w->w || wh != w->h) && ww >= DASH_FOCUS_MIN_W && wh >= DASH_FOCUS_MIN_H + DASH_WINDOW_FOOTER_H &&
      make_canvas(w, ww, wh, err))
    return -1;
  uint64_t t_draw = vtime_mono_ns();
  cairo_t *cr = cairo_create(w->canvas);
  int rc = 0;
  if (w->focused >= 0) {
    rc = dash_draw_focus(d, w->focused, cr, w->w, w->h - DASH_WINDOW_FOOTER_H, err);
  } else {
    cairo_set_source_rgb(cr, 0.07, 0.07, 0.08);
    cairo_paint(cr);
    int gw, gh;
    dash_grid_size(d, &gw, &gh);
    w->gx = gw < w->w ? (w->w - gw) / 2 : 0;
    w->gy = gh < w->h - DASH_WINDOW_FOOTER_H ? (w->h - DASH_WINDOW_FOOTER_H - gh) / 2 : 0;
    dash_draw_grid(d, cr, w->gx, w->gy, err);
  }
  footer(w, cr);
  cairo_destroy(cr);
  if (rc) return -1;
  cairo_surface_flush(w->canvas);
  if (sdl_window_present(&w->sw, SDL_PIXELFORMAT_RGB888, cairo_image_surface_get_data(w->canvas), w->w, w->h,
                         cairo_image_surface_get_stride(w->canvas), err))
    return -1;
  w->shown++;
  w->draw_s += (double)(vtime_mono_ns() - t_draw) * 1e-9;
  return quit;
}

long dash_window_snapshot(dash_window_t *w, const char *path, verr_t *err) {
  cairo_surface_t *back = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w->w, w->h);
  if (cairo_surface_status(back) != CAIRO_STATUS_SUCCESS) {
    cairo_surface_destroy(back);
    return verr_set(err, "out of memory"), -1L;
  }
  cairo_surface_flush(back);
  int stride = cairo_image_surface_get_stride(back);
  unsigned char *b = cairo_image_surface_get_data(back);
  if (sdl_window_read_back(&w->sw, SDL_PIXELFORMAT_RGB888, b, stride, err)) {
    cairo_surface_destroy(back);
    return -1;
  }
  cairo_surface_mark_dirty(back);
  const unsigned char *c = cairo_image_surface_get_data(w->canvas);
  long differ = 0;
  for (int y = 0; y < w->h; y++) {
    const uint32_t *rb = (const uint32_t *)(b + (size_t)y * stride);
    const uint32_t *rc = (const uint32_t *)(c + (size_t)y * cairo_image_surface_get_stride(w->canvas));
    for (int x = 0; x < w->w; x++) differ += (rb[x] & 0xffffffu) != (rc[x] & 0xffffffu);
  }
  long rc = differ;
  if (cairo_surface_write_to_png(back, path) != CAIRO_STATUS_SUCCESS) rc = verr_set(err, "cannot write %s", path);
  cairo_surface_destroy(back);
  return rc;
}
