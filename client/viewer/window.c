/* SPDX-License-Identifier: Apache-2.0 */
#include "window.h"

#include <SDL.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dds/vdds_config.h"
#include "view/camera.h"
#include "view/frame_log.h"
#include "input_drive.h"
#include "window/input_map.h"
#include "window/input_script.h"
#include "view/png_write.h"
#include "view/render.h"
#include "view/scene_draw.h"
#include "view/scene_view.h"
#include "window/sdl_window.h"
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
  sdl_window_t sw;
  uint8_t *flip; /* one frame top-down for the texture */
  render_t *r;
  scene_view_t sv;
  int sv_open, window_opened;
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
  verr_t err = {{0}};
  w->flip = malloc((size_t)w->o->width * (size_t)w->o->height * 3);
  if (!w->flip) {
    fprintf(stderr, "viscera-viewer: --window: out of memory\n");
    return -1;
  }
  if (sdl_window_open(&w->sw, "viscera", w->o->width, w->o->height, 0, &err)) {
    fprintf(stderr, "viscera-viewer: --window: %s\n", err.msg);
    return -1;
  }
  return 0;
}

static void close_window(win_t *w) {
  free(w->flip);
  sdl_window_close(&w->sw);
}

static int present(win_t *w, const uint8_t *img) {
  /* The renderer's rows are bottom-up (OpenGL order); the texture's top-down. */
  size_t row = (size_t)w->o->width * 3;
  for (int y = 0; y < w->o->height; y++)
    memcpy(w->flip + (size_t)y * row, img + (size_t)(w->o->height - 1 - y) * row, row);
  verr_t err = {{0}};
  if (sdl_window_present(&w->sw, SDL_PIXELFORMAT_RGB24, w->flip, w->o->width, w->o->height, (int)row, &err)) {
    fprintf(stderr, "viscera-viewer: --window: %s\n", err.msg);
    return -1;
  }
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
  if (sdl_window_read_back(&w->sw, SDL_PIXELFORMAT_RGB24, back, (int)row, err)) {
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
  SDL_SetWindowTitle(w->sw.window, title);
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
  int told_nothing = 0;
  const uint8_t *last_img = NULL;
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
    if (vdds_nothing_seen_due(&told_nothing, w->sv.have_scene || vdds_matched_writers(w->sv.rd_scene), t0, now))
      vdds_explain_nothing_seen(stderr, "viewer", "no server publishes a scene here", o->domain, o->partition,
                                VDDS_NOTHING_SEEN_S);
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
      while ((se = input_script_due(&w->script, (double)(now - cam_ns) * 1e-9))) sdl_window_push_input(&w->sw, &se->ev);
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
  w.window_opened = 1;
  if (open_window(&w)) goto out;
  status = run(&w, stop);
out:
  input_drive_stop(&w.drive);
  if (w.window_opened) close_window(&w);
  if (w.sv_open) scene_view_close(&w.sv);
  if (w.r) render_close(w.r);
  if (w.fl_open && frame_log_close(&w.fl, &err)) {
    fprintf(stderr, "viscera-viewer: %s\n", err.msg);
    status = 1;
  }
  input_script_free(&w.script);
  return status;
}
