/* SPDX-License-Identifier: Apache-2.0 */
#include "dash_run.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cairo.h>

#include "dash_draw.h"
#include "plot/plot_cleanup.h"
#include "seat.h"
#include "dds/vdds_config.h"
#include "dds/vdds_ident.h"
#include "vsignal.h"
#include "vtime.h"
#ifdef VISCERA_HAVE_WINDOW
#include "dash_window.h"
#endif

static volatile sig_atomic_t g_stop;
static void on_signal(int sig) {
  (void)sig;
  g_stop = 1;
}

static int write_png(cairo_surface_t *surf, const char *out, const char *kind, int frame) {
  char png[1100];
  snprintf(png, sizeof png, "%s/%s_%05d.png", out, kind, frame);
  if (cairo_surface_write_to_png(surf, png) == CAIRO_STATUS_SUCCESS) return 0;
  fprintf(stderr, "viscera-dashboard: cannot write %s\n", png);
  return -1;
}

/* Each change of who drives a tool, on stdout: the instructor's log (and
 * what the tests read). */
static void log_roles(seat_t *s) {
  for (int t = 0; t < SCENE_VIEW_MAX_TOOLS; t++) {
    seat_role_t *r = &s->roles[t];
    if (!r->changed) continue;
    r->changed = 0;
    char txt[160];
    printf("dashboard: %s tool %d driven by: %s\n", s->partition, t,
           seat_role_text(txt, sizeof txt, r->have, r->owner, r->guide, r->authority));
    fflush(stdout);
  }
}

/* Once, VDDS_NOTHING_SEEN_S after the start: when no seat has a server,
 * why that may be (vdds_config.h); when only some have none, which. */
static void tell_empty_seats(const seat_t *seats, int n, const dash_options_t *o, int *told, uint64_t t0,
                             uint64_t now) {
  int seen = 0;
  for (int i = 0; i < n; i++) seen += seats[i].sv.have_scene || vdds_matched_writers(seats[i].sv.rd_scene) > 0;
  if (!vdds_nothing_seen_due(told, seen == n, t0, now)) return;
  if (seen == 0) {
    char parts[160];
    snprintf(parts, sizeof parts, "%s/seat%02d..seat%02d", o->prefix, o->first, o->first + n - 1);
    vdds_explain_nothing_seen(stderr, "viscera-dashboard", "no seat has a server", o->domain, parts,
                              VDDS_NOTHING_SEEN_S);
    return;
  }
  for (int i = 0; i < n; i++)
    if (!seats[i].sv.have_scene && vdds_matched_writers(seats[i].sv.rd_scene) == 0)
      fprintf(stderr, "viscera-dashboard: no server seen in %s after %.0f s (%d other seat(s) live)\n",
              seats[i].partition, VDDS_NOTHING_SEEN_S, seen);
}

int dash_run(const dash_options_t *o) {
  const char *prefix = o->prefix, *out = o->out, *script = o->script;
  int nseats = o->nseats, first = o->first, tw = o->tw, th = o->th, cols = o->cols, interval_ms = o->interval_ms;
  int focus_seat = o->focus_seat, fw = o->fw, fh = o->fh, window = o->window, out_set = o->out_set;
  double duration = o->duration, refresh_hz = o->refresh_hz;
  int domain = o->domain;
  verr_t err = {{0}};
  (void)script;
  (void)refresh_hz;
  if (cols == 0) cols = (int)ceil(sqrt((double)nseats));
  if (cols > nseats) cols = nseats;
  /* A window writes PNGs only when asked; the headless dashboard always does. */
  int pngs = !window || out_set;
  FILE *csv = NULL;
  if (pngs) {
    if (mkdir(out, 0755) && errno != EEXIST) {
      fprintf(stderr, "viscera-dashboard: cannot create %s: %s\n", out, strerror(errno));
      return 1;
    }
    char csv_path[1024];
    snprintf(csv_path, sizeof csv_path, "%s/dashboard.csv", out);
    csv = fopen(csv_path, "w");
    if (!csv) {
      fprintf(stderr, "viscera-dashboard: cannot write %s: %s\n", csv_path, strerror(errno));
      return 1;
    }
    fprintf(csv, "frame,wall_s,seat,have_scene,force_n,peak_n,alert,crossings_st,crossings_mpf,crossings_sft,"
                 "client_lost,focused,client_left,paused\n");
  }

  static seat_t seats[MAX_SEATS];
  static dash_t dash;
#ifdef VISCERA_HAVE_WINDOW
  static dash_window_t dw;
#endif
  int rc = 0, opened = 0, window_open = 0;
  cairo_surface_t *grid = NULL, *focus = NULL;
  for (int i = 0; i < nseats; i++) {
    char part[128];
    snprintf(part, sizeof part, "%s/seat%02d", prefix, first + i);
    if (seat_open(&seats[i], domain, part, &err)) {
      fprintf(stderr, "viscera-dashboard: %s: %s\n", part, err.msg);
      rc = 1;
      goto done;
    }
    opened++;
  }
  if (dash_open(&dash, seats, nseats, cols, tw, th, &err)) {
    fprintf(stderr, "viscera-dashboard: %s\n", err.msg);
    rc = 1;
    goto done;
  }
  int W, H;
  dash_grid_size(&dash, &W, &H);
  grid = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
  if (focus_seat) focus = cairo_image_surface_create(CAIRO_FORMAT_RGB24, fw, fh);
#ifdef VISCERA_HAVE_WINDOW
  if (window) {
    window_open = 1;
    if (dash_window_open(&dw, W > fw ? W : fw, (H > fh ? H : fh) + DASH_WINDOW_FOOTER_H, script, &err)) {
      fprintf(stderr, "viscera-dashboard: --window: %s\n", err.msg);
      rc = 1;
      goto done;
    }
    if (focus_seat) dw.focused = focus_seat - first; /* the window starts on that seat */
    printf("dashboard: window open (SDL video driver %s)\n", SDL_GetCurrentVideoDriver());
    fflush(stdout);
  }
#endif
  fprintf(stderr, "viscera-dashboard: %d seat(s) %s/seat%02d..seat%02d on domain %d, %dx%d grid%s%s%s\n", nseats,
          prefix, first, first + nseats - 1, domain, cols, dash.rows, window ? ", window" : "",
          pngs ? ", frames to " : "", pngs ? out : "");
  vsignal_on_stop(on_signal, 0);
  const uint64_t sample_ns = (uint64_t)(1e9 / DASH_SAMPLE_HZ);
  const uint64_t tick_ns = window ? (uint64_t)(1e9 / refresh_hz) : sample_ns;
  uint64_t t0 = vtime_mono_ns(), next_tick = t0, next_sample = t0, last_sample = t0;
  uint64_t next_frame = t0 + (uint64_t)interval_ms * 1000000ull;
  int frame = 0, told_empty = 0;
  while (!g_stop) {
    uint64_t now_ns = vtime_mono_ns();
    double now = (double)(now_ns - t0) * 1e-9;
    if (duration > 0 && now >= duration) break;
    tell_empty_seats(seats, nseats, o, &told_empty, t0, now_ns);
    for (int i = 0; i < nseats; i++) {
      if (seat_poll(&seats[i], now, &err)) fprintf(stderr, "viscera-dashboard: %s: %s\n", seats[i].partition, err.msg);
      log_roles(&seats[i]);
    }
    if (now_ns >= next_sample) {
      /* The history is at DASH_SAMPLE_HZ whatever the refresh rate. */
      for (int i = 0; i < nseats; i++) seat_sample(&seats[i], (double)(now_ns - last_sample) * 1e-9);
      last_sample = now_ns;
      next_sample += sample_ns;
      if (next_sample <= now_ns) next_sample = now_ns + sample_ns;
    }
    dash_update(&dash);
    int focused = focus_seat ? focus_seat - first : -1;
#ifdef VISCERA_HAVE_WINDOW
    if (window) {
      int q = dash_window_tick(&dw, &dash, &err);
      if (q < 0) {
        fprintf(stderr, "viscera-dashboard: --window: %s\n", err.msg);
        rc = 1;
        break;
      }
      if (q) break;
      focused = dw.focused;
    }
#endif
    if (pngs && now_ns >= next_frame) {
      next_frame += (uint64_t)interval_ms * 1000000ull;
      cairo_t *cr = cairo_create(grid);
      cairo_set_source_rgb(cr, 0.07, 0.07, 0.08);
      cairo_paint(cr);
      dash_draw_grid(&dash, cr, 0, 0, &err);
      cairo_destroy(cr);
      write_png(grid, out, "dashboard", frame);
      if (focused >= 0) {
        /* The window's focused view as shown; headless, the --focus view. */
        cairo_surface_t *fs = focus;
#ifdef VISCERA_HAVE_WINDOW
        if (window) fs = dw.canvas;
#endif
        if (!window) {
          cr = cairo_create(focus);
          if (dash_draw_focus(&dash, focused, cr, fw, fh, &err))
            fprintf(stderr, "viscera-dashboard: focus view: %s\n", err.msg);
          cairo_destroy(cr);
        }
        write_png(fs, out, "focus", frame);
      }
      for (int i = 0; i < nseats; i++) {
        seat_t *s = &seats[i];
        float st, mpf, sft, maxf;
        double f = seat_force(s, &st, &mpf, &sft, &maxf);
        fprintf(csv, "%d,%.3f,%s,%d,%.4f,%.4f,%s,%u,%u,%u,%d,%d,%d,%d\n", frame, now, s->partition, s->sv.have_scene, f,
                s->peak, seat_level_name(s->alert), s->crossings[0], s->crossings[1], s->crossings[2], s->client_lost,
                i == focused, s->client_left, s->paused);
      }
      fflush(csv);
      frame++;
    }
    next_tick += tick_ns;
    if (next_tick <= vtime_mono_ns()) next_tick = vtime_mono_ns() + tick_ns / 4; /* behind: do not spin */
    vtime_sleep_until(next_tick);
  }
#ifdef VISCERA_HAVE_WINDOW
  if (window_open && dw.canvas) {
    if (pngs) {
      char path[1100];
      snprintf(path, sizeof path, "%s/window.png", out);
      long differ = dash_window_snapshot(&dw, path, &err);
      if (differ < 0)
        fprintf(stderr, "viscera-dashboard: %s\n", err.msg);
      else
        printf("dashboard: window.png written; %ld of %d window pixels differ from the drawing\n", differ, dw.w * dw.h);
    }
    printf("dashboard: window closed after %.1f s, %ld frames shown (%.1f ms each to draw and present), %ld view "
           "changes\n",
           (double)(vtime_mono_ns() - t0) * 1e-9, dw.shown, dw.shown ? dw.draw_s * 1e3 / (double)dw.shown : 0.0,
           dw.changes);
  }
#endif
  (void)window_open;
  fprintf(stderr, "viscera-dashboard: %d frame(s) written\n", frame);
done:
#ifdef VISCERA_HAVE_WINDOW
  if (window_open) dash_window_close(&dw);
#endif
  if (grid) cairo_surface_destroy(grid);
  if (focus) cairo_surface_destroy(focus);
  dash_close(&dash);
  for (int i = 0; i < opened; i++) seat_close(&seats[i]);
  if (csv) fclose(csv);
  plot_cleanup(); /* cairo's and fontconfig's process caches (LeakSanitizer) */
  return rc;
}
