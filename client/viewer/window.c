#include "window.h"

#include <SDL.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera.h"
#include "frame_log.h"
#include "input_drive.h"
#include "input_map.h"
#include "input_script.h"
#include "png_write.h"
#include "render.h"
#include "scene_draw.h"
#include "scene_view.h"
#include "vtime.h"

#define SUPERSAMPLE 2
#define KEYFRAME_GRACE_NS 500000000ull /* as in main.c: wait for the other organs' keyframes */
#define FRAME_NS 16666667ull           /* display-rate cap, 60 Hz */
#define DRIVE_RATE_HZ 1000.0
#define TITLE_EVERY_NS 200000000ull
/* Without --duration a scripted session closes this long after its last
 * event, so a demo or test ends by itself whatever the start-up time. */
#define SCRIPT_TAIL_S 1.0

typedef struct win {
  const viewer_opts_t *o;
  SDL_Window *window;
  SDL_Renderer *sdl;
  SDL_Texture *tex;
  uint8_t *flip; /* one frame top-down for the texture */
  render_t *r;
  scene_view_t sv;
  int sv_open, sdl_inited;
  camera_t cam;
  int have_cam;
  input_state_t in;
  input_drive_t drive;
  input_script_t script;
  frame_log_t fl;
  int fl_open;
  unsigned long rejects_printed;
} win_t;

static void log_reject(void *ctx, const char *msg) {
  unsigned long *n = ctx;
  if (++*n <= 20) fprintf(stderr, "viewer: rejected #%lu: %s\n", *n, msg);
}

/* SDL keys to the mapping's keys; everything else is ignored. */
static input_key_t map_key(SDL_Keycode k) {
  switch (k) {
  case SDLK_w:
    return INPUT_KEY_W;
  case SDLK_s:
    return INPUT_KEY_S;
  case SDLK_r:
    return INPUT_KEY_R;
  case SDLK_SPACE:
    return INPUT_KEY_SPACE;
  default:
    return INPUT_KEY_OTHER;
  }
}

static SDL_Keycode sdl_key(input_key_t k) {
  switch (k) {
  case INPUT_KEY_W:
    return SDLK_w;
  case INPUT_KEY_S:
    return SDLK_s;
  case INPUT_KEY_R:
    return SDLK_r;
  case INPUT_KEY_SPACE:
    return SDLK_SPACE;
  default:
    return SDLK_UNKNOWN;
  }
}

/* A scripted event as the SDL event a user would have produced. */
static void push_scripted(const input_event_t *e, Uint32 window_id) {
  SDL_Event ev;
  memset(&ev, 0, sizeof ev);
  switch (e->kind) {
  case INPUT_MOTION:
    ev.type = SDL_MOUSEMOTION;
    ev.motion.windowID = window_id;
    ev.motion.xrel = (Sint32)lround(e->dx);
    ev.motion.yrel = (Sint32)lround(e->dy);
    break;
  case INPUT_WHEEL:
    ev.type = SDL_MOUSEWHEEL;
    ev.wheel.windowID = window_id;
    ev.wheel.y = e->n;
    ev.wheel.direction = SDL_MOUSEWHEEL_NORMAL;
    break;
  case INPUT_KEY_DOWN:
  case INPUT_KEY_UP:
    ev.type = e->kind == INPUT_KEY_DOWN ? SDL_KEYDOWN : SDL_KEYUP;
    ev.key.windowID = window_id;
    ev.key.state = e->kind == INPUT_KEY_DOWN ? SDL_PRESSED : SDL_RELEASED;
    ev.key.keysym.sym = sdl_key(e->key);
    break;
  case INPUT_BUTTON_DOWN:
  case INPUT_BUTTON_UP:
    ev.type = e->kind == INPUT_BUTTON_DOWN ? SDL_MOUSEBUTTONDOWN : SDL_MOUSEBUTTONUP;
    ev.button.windowID = window_id;
    ev.button.button = SDL_BUTTON_LEFT;
    ev.button.state = e->kind == INPUT_BUTTON_DOWN ? SDL_PRESSED : SDL_RELEASED;
    break;
  }
  SDL_PushEvent(&ev);
}

/* Handles one SDL event; returns 1 when the user asked to quit. */
static int handle_event(win_t *w, const SDL_Event *ev, int driving) {
  input_event_t e;
  memset(&e, 0, sizeof e);
  switch (ev->type) {
  case SDL_QUIT:
    return 1;
  case SDL_KEYDOWN:
  case SDL_KEYUP:
    if (ev->key.keysym.sym == SDLK_ESCAPE) return 1;
    if (ev->key.repeat) return 0; /* held keys act through input_map_advance */
    e.kind = ev->type == SDL_KEYDOWN ? INPUT_KEY_DOWN : INPUT_KEY_UP;
    e.key = map_key(ev->key.keysym.sym);
    if (e.key == INPUT_KEY_OTHER) return 0;
    break;
  case SDL_MOUSEMOTION:
    e.kind = INPUT_MOTION;
    e.dx = ev->motion.xrel;
    e.dy = ev->motion.yrel;
    break;
  case SDL_MOUSEWHEEL:
    e.kind = INPUT_WHEEL;
    e.n = ev->wheel.direction == SDL_MOUSEWHEEL_FLIPPED ? -ev->wheel.y : ev->wheel.y;
    break;
  case SDL_MOUSEBUTTONDOWN:
  case SDL_MOUSEBUTTONUP:
    if (ev->button.button != SDL_BUTTON_LEFT) return 0;
    e.kind = ev->type == SDL_MOUSEBUTTONDOWN ? INPUT_BUTTON_DOWN : INPUT_BUTTON_UP;
    break;
  default:
    return 0;
  }
  if (driving && w->have_cam) input_map_apply(&w->in, &e);
  return 0;
}

static int open_window(win_t *w) {
  /* The frame is ready-made pixels: SDL's software renderer presents it on
   * any X server (Xvfb included) without pulling a second GL into the
   * process (see window.h); SDL_RENDER_DRIVER still overrides. */
  SDL_SetHint(SDL_HINT_RENDER_DRIVER, "software");
  /* Left to itself SDL backs the software window surface with an OpenGL
   * renderer; with OSMesa's GL symbols in the process that crashed inside
   * Mesa's GLX driver (seen under Xvfb). The X11 framebuffer (XShm) path
   * needs no GL. */
  SDL_SetHint(SDL_HINT_FRAMEBUFFER_ACCELERATION, "0");
  if (SDL_Init(SDL_INIT_VIDEO) != 0) {
    fprintf(stderr,
            "viscera-viewer: --window: cannot open a display: %s (is DISPLAY set? the offscreen mode "
            "needs none)\n",
            SDL_GetError());
    SDL_Quit();
    return -1;
  }
  w->sdl_inited = 1;
  w->window = SDL_CreateWindow("viscera", SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, w->o->width, w->o->height,
                               SDL_WINDOW_SHOWN);
  if (w->window) w->sdl = SDL_CreateRenderer(w->window, -1, 0);
  if (w->sdl)
    w->tex = SDL_CreateTexture(w->sdl, SDL_PIXELFORMAT_RGB24, SDL_TEXTUREACCESS_STREAMING, w->o->width, w->o->height);
  w->flip = malloc((size_t)w->o->width * (size_t)w->o->height * 3);
  if (!w->window || !w->sdl || !w->tex || !w->flip) {
    fprintf(stderr, "viscera-viewer: --window: cannot create the window: %s\n",
            w->flip ? SDL_GetError() : "out of memory");
    return -1;
  }
  return 0;
}

static void close_window(win_t *w) {
  free(w->flip);
  if (w->tex) SDL_DestroyTexture(w->tex);
  if (w->sdl) SDL_DestroyRenderer(w->sdl);
  if (w->window) SDL_DestroyWindow(w->window);
  SDL_Quit();
}

static int present(win_t *w, const uint8_t *img) {
  /* The renderer's rows are bottom-up (OpenGL order); the texture's top-down. */
  size_t row = (size_t)w->o->width * 3;
  for (int y = 0; y < w->o->height; y++)
    memcpy(w->flip + (size_t)y * row, img + (size_t)(w->o->height - 1 - y) * row, row);
  if (SDL_UpdateTexture(w->tex, NULL, w->flip, (int)row) != 0 || SDL_RenderClear(w->sdl) != 0 ||
      SDL_RenderCopy(w->sdl, w->tex, NULL, NULL) != 0) {
    fprintf(stderr, "viscera-viewer: --window: %s\n", SDL_GetError());
    return -1;
  }
  SDL_RenderPresent(w->sdl);
  return 0;
}

/* What the window shows, read back from SDL after the last frame: written
 * as DIR/window.png and compared with the renderer's frame, so a test (or a
 * doubtful user) can see that the window presents exactly the rendered
 * pixels, right side up. Returns the number of differing pixels, -1 when
 * the read-back failed. */
static long window_snapshot(win_t *w, verr_t *err) {
  int wd = w->o->width, ht = w->o->height;
  size_t row = (size_t)wd * 3;
  uint8_t *back = malloc(row * (size_t)ht);
  if (!back) return verr_set(err, "out of memory"), -1L;
  if (SDL_RenderReadPixels(w->sdl, NULL, SDL_PIXELFORMAT_RGB24, back, (int)row) != 0) {
    verr_set(err, "window read-back: %s", SDL_GetError());
    free(back);
    return -1;
  }
  long differ = 0;
  for (size_t i = 0; i < row * (size_t)ht; i += 3)
    differ += back[i] != w->flip[i] || back[i + 1] != w->flip[i + 1] || back[i + 2] != w->flip[i + 2];
  char path[FRAME_LOG_DIR_LEN + 32];
  snprintf(path, sizeof path, "%s/window.png", w->fl.dir);
  int rc = png_write_rgb(path, wd, ht, back, 0, err);
  free(back);
  return rc ? -1 : differ;
}

/* Writes img as the next PNG frame with its frames.csv row. */
static int write_png(win_t *w, const uint8_t *img, double wall_ms, verr_t *err) {
  char path[FRAME_LOG_DIR_LEN + 32];
  frame_row_t row = {.wall_ms = wall_ms};
  scene_draw_readouts(&w->cam, &w->sv, &row);
  if (frame_log_next_path(&w->fl, path, sizeof path, err) ||
      png_write_rgb(path, w->o->width, w->o->height, img, 1, err) || frame_log_add(&w->fl, &row, err))
    return -1;
  return 0;
}

static void update_title(win_t *w, int driving) {
  char title[256];
  int p = driving ? w->o->drive_tool : scene_view_primary_tool(&w->sv);
  const sv_tool_t *t = p >= 0 && p < SCENE_VIEW_MAX_TOOLS ? &w->sv.tools[p] : NULL;
  double f = t && t->have_contact ? sqrt((double)t->force[0] * t->force[0] + (double)t->force[1] * t->force[1] +
                                         (double)t->force[2] * t->force[2])
                                  : 0;
  if (driving)
    snprintf(title, sizeof title, "viscera %s - driving tool %d at (%.1f, %.1f, %.1f) mm%s - force %.2f N",
             w->sv.have_scene ? w->sv.scene_name : "", p, w->in.pos[0] * 1e3, w->in.pos[1] * 1e3, w->in.pos[2] * 1e3,
             w->in.buttons & 1 ? " [button]" : "", f);
  else
    snprintf(title, sizeof title, "viscera %s - force %.2f N", w->sv.have_scene ? w->sv.scene_name : "", f);
  SDL_SetWindowTitle(w->window, title);
}

static int run(win_t *w, volatile sig_atomic_t *stop) {
  const viewer_opts_t *o = w->o;
  int driving = o->drive_tool >= 0;
  verr_t err = {{0}};
  const uint64_t t0 = vtime_mono_ns();
  const uint64_t duration_ns = (uint64_t)(o->duration_s * 1e9);
  const uint64_t interval_ns = (uint64_t)o->interval_ms * 1000000ull;
  uint64_t first_key_ns = 0, cam_ns = 0, last_ns = t0, next_png = 0, next_title = 0;
  long presented = 0;
  const uint8_t *last_img = NULL;
  Uint32 window_id = SDL_GetWindowID(w->window);
  while (!*stop) {
    uint64_t now = vtime_mono_ns();
    if (duration_ns && now - t0 >= duration_ns) break;
    if (!duration_ns && w->script.n && w->script.next == w->script.n &&
        (double)(now - cam_ns) * 1e-9 >= input_script_duration(&w->script) + SCRIPT_TAIL_S)
      break;
    if (scene_view_poll(&w->sv, &err) < 0) {
      fprintf(stderr, "viscera-viewer: %s\n", err.msg);
      return 1;
    }
    if (!w->have_cam && scene_view_any_keyframe(&w->sv)) {
      if (!first_key_ns) first_key_ns = now;
      double bmin[3], bmax[3];
      if ((scene_view_complete(&w->sv) || now - first_key_ns >= KEYFRAME_GRACE_NS) &&
          scene_view_key_bounds(&w->sv, bmin, bmax) == 0 &&
          camera_frame(&w->cam, bmin, bmax, o->width, o->height) == 0 &&
          input_map_init(&w->in, &w->cam, bmin, bmax) == 0) {
        w->have_cam = 1;
        cam_ns = now;
        next_png = now;
        if (!o->quiet) {
          printf("viewer: window open (SDL video driver %s), camera fixed%s\n", SDL_GetCurrentVideoDriver(),
                 driving ? "; driving the tool (mouse, wheel, W/S, "
                           "left button/space, R)"
                         : "");
          fflush(stdout);
        }
      }
    }
    /* Scripted input becomes SDL events, timed from the camera fix. */
    if (w->have_cam && w->script.n) {
      const input_script_event_t *se;
      while ((se = input_script_due(&w->script, (double)(now - cam_ns) * 1e-9))) push_scripted(&se->ev, window_id);
    }
    SDL_Event ev;
    while (SDL_PollEvent(&ev))
      if (handle_event(w, &ev, driving)) *stop = 1;
    if (driving && w->have_cam) {
      input_map_advance(&w->in, (double)(now - last_ns) * 1e-9);
      const sv_tool_t *t = &w->sv.tools[o->drive_tool];
      float max_force = t->listed && t->max_force > 0 ? t->max_force : SCENE_VIEW_TOOL_MAX_FORCE;
      input_drive_set(&w->drive, w->in.pos, w->in.buttons, max_force);
    }
    last_ns = now;
    if (w->have_cam) {
      const uint8_t *img = scene_draw(w->r, &w->cam, &w->sv, o->tools, &err);
      if (!img || present(w, img)) {
        if (!img) fprintf(stderr, "viscera-viewer: %s\n", err.msg);
        return 1;
      }
      presented++;
      last_img = img;
      if (w->fl_open && interval_ns && now >= next_png) {
        if (write_png(w, img, (double)(now - t0) * 1e-6, &err)) {
          fprintf(stderr, "viscera-viewer: %s\n", err.msg);
          return 1;
        }
        next_png += interval_ns;
        if (next_png <= now) next_png = now + interval_ns;
      }
      if (now >= next_title) {
        update_title(w, driving);
        next_title = now + TITLE_EVERY_NS;
      }
    }
    uint64_t wake = now + FRAME_NS;
    if (duration_ns && t0 + duration_ns < wake) wake = t0 + duration_ns;
    vtime_sleep_until(wake);
  }
  if (w->fl_open && last_img) {
    /* The state at exit as the last frame, so the index ends where the
     * session ended whatever the interval. */
    if (write_png(w, last_img, (double)(vtime_mono_ns() - t0) * 1e-6, &err)) {
      fprintf(stderr, "viscera-viewer: %s\n", err.msg);
      return 1;
    }
    /* Read back before any other present: what is on screen now is that
     * same frame, drawn into w->flip. */
    long differ = window_snapshot(w, &err);
    if (differ < 0)
      fprintf(stderr, "viscera-viewer: %s\n", err.msg);
    else
      printf("viewer: window.png written; %ld of %d window pixels differ from the rendered frame\n", differ,
             o->width * o->height);
  }
  printf("viewer: window closed after %.1f s, %ld frames shown", (double)(vtime_mono_ns() - t0) * 1e-9, presented);
  if (driving)
    printf(", %llu commands sent for tool %d, %llu input events, tool at (%.4f, %.4f, %.4f)",
           (unsigned long long)input_drive_sent(&w->drive), o->drive_tool, (unsigned long long)w->in.events,
           w->in.pos[0], w->in.pos[1], w->in.pos[2]);
  printf("\n");
  if (w->fl_open) printf("viewer: %ld frames written to %s\n", w->fl.frames, o->out_dir);
  printf("SUMMARY frames=%ld rejected=%lu shown=%ld\n", w->fl_open ? w->fl.frames : 0L, w->sv.rejected, presented);
  return 0;
}

int window_main(const viewer_opts_t *o, volatile sig_atomic_t *stop) {
  static win_t w; /* large (scene view); one per process */
  memset(&w, 0, sizeof w);
  w.o = o;
  verr_t err = {{0}};
  int status = 1;
  if (o->script_input && input_script_load(o->script_input, &w.script, &err)) {
    fprintf(stderr, "viscera-viewer: --script-input: %s\n", err.msg);
    return 2;
  }
  if (render_open(&w.r, o->width, o->height, SUPERSAMPLE, &err)) {
    fprintf(stderr, "viscera-viewer: renderer: %s\n", err.msg);
    goto out;
  }
  if (o->out_set) {
    if (frame_log_open(&w.fl, o->out_dir, &err)) {
      fprintf(stderr, "viscera-viewer: output: %s\n", err.msg);
      goto out;
    }
    w.fl_open = 1;
  }
  if (scene_view_open(&w.sv, o->domain, o->partition, log_reject, &w.rejects_printed, &err)) {
    fprintf(stderr, "viscera-viewer: %s\n", err.msg);
    goto out;
  }
  w.sv_open = 1;
  if (o->drive_tool >= 0 && input_drive_start(&w.drive, &w.sv.dds, (uint32_t)o->drive_tool, DRIVE_RATE_HZ, &err)) {
    fprintf(stderr, "viscera-viewer: --drive: %s\n", err.msg);
    goto out;
  }
  if (open_window(&w)) goto out;
  status = run(&w, stop);
out:
  input_drive_stop(&w.drive);
  if (w.sdl_inited) close_window(&w);
  if (w.sv_open) scene_view_close(&w.sv);
  if (w.r) render_close(w.r);
  if (w.fl_open && frame_log_close(&w.fl, &err)) {
    fprintf(stderr, "viscera-viewer: %s\n", err.msg);
    status = 1;
  }
  input_script_free(&w.script);
  return status;
}
