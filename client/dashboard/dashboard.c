/* viscera-dashboard: the instructor's view of a lab's seats (issue 7).
 *
 * One tile per seat (partition PREFIX/seatNN): the organ and tool as the
 * viewer draws them, the trainee's contact force over the last 30 s against
 * the seat's palpation thresholds, and an alert frame (amber above ST, red
 * above MPF, magenta above SFT) for SEAT_ALERT_HOLD_S after the server
 * reports a crossing. Seats without a server say so. A seat can be focused:
 * its scene large, force graph with axes, level badge, peak, time above each
 * threshold, who drives and guides its tool, its last events (dash_draw.h).
 *
 * Output: the grid as PNG frames at an interval with a CSV row per seat and
 * frame, so a session's alerts can be checked afterwards; with --focus SEAT
 * also the focus view of that seat (focus_NNNNN.png) without any display;
 * with --window the same pictures live in an SDL2 window (dash_window.h),
 * where keys and clicks choose the view, and PNGs only when --out is given
 * (a focused window's view is written as focus_NNNNN.png). */
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
#include "dds/vdds_ident.h"
#include "vsignal.h"
#include "vtime.h"
#ifdef VISCERA_HAVE_WINDOW
#include "dash_window.h"
#endif

#define MAX_SEATS 32
#define FOCUS_W 1024 /* default focus view / window size */
#define FOCUS_H 680

static volatile sig_atomic_t g_stop;
static void on_signal(int sig) {
  (void)sig;
  g_stop = 1;
}

static void usage(FILE *f) {
  fprintf(f,
          "usage: viscera-dashboard [options]\n"
          "  --prefix P          lab partition prefix; seats are P/seatNN (default lab)\n"
          "  --seats N           number of seats (default 4, at most %d)\n"
          "  --first K           first seat number (default 1)\n"
          "  --tile WxH          tile size in pixels (default 320x240)\n"
          "  --cols C            tiles per row (default: square-ish grid)\n"
          "  --out DIR           PNG frames and dashboard.csv (default ./dashboard)\n"
          "  --interval-ms MS    a frame every MS ms (default 1000)\n"
          "  --duration S        stop after S s (default: until SIGINT/SIGTERM)\n"
          "  --focus SEAT        also write the focus view of seat number SEAT (PNG, no display needed);\n"
          "                      with --window: start focused on it\n"
          "  --size WxH          focus view size, and the window's first size (default %dx%d)\n"
          "  --window            show the dashboard live in a window (SDL2); PNGs then only with --out\n"
          "  --refresh-hz HZ     window refresh rate (default 15, 1..60)\n"
          "  --script-input F    window: timed keys and clicks from F (viewer's input script format)\n"
          "  --domain N          DDS domain id (default: $VISCERA_DOMAIN or 0)\n"
          "  --help              this text\n"
          "window keys: 1-9 or a click on a tile: focus that seat; Tab / Shift+Tab: next / previous\n"
          "  seat; Esc or a click: back to the grid; Q or closing the window: quit\n",
          MAX_SEATS, FOCUS_W, FOCUS_H);
}

static int parse_size(const char *s, int *w, int *h, int minw, int minh, int max) {
  return sscanf(s, "%dx%d", w, h) == 2 && *w >= minw && *h >= minh && *w <= max && *h <= max ? 0 : -1;
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

int main(int argc, char **argv) {
  vdds_set_role("dashboard"); /* announced in the participant USER_DATA */
  static const struct option opts[] = {{"prefix", required_argument, 0, 'p'},
                                       {"seats", required_argument, 0, 'n'},
                                       {"first", required_argument, 0, 'f'},
                                       {"tile", required_argument, 0, 't'},
                                       {"cols", required_argument, 0, 'c'},
                                       {"out", required_argument, 0, 'o'},
                                       {"interval-ms", required_argument, 0, 'i'},
                                       {"duration", required_argument, 0, 'd'},
                                       {"focus", required_argument, 0, 'F'},
                                       {"size", required_argument, 0, 's'},
                                       {"window", no_argument, 0, 'W'},
                                       {"refresh-hz", required_argument, 0, 'r'},
                                       {"script-input", required_argument, 0, 'S'},
                                       {"domain", required_argument, 0, 'D'},
                                       {"help", no_argument, 0, 'h'},
                                       {0, 0, 0, 0}};
  const char *prefix = "lab", *out = "dashboard", *script = NULL;
  int nseats = 4, first = 1, tw = 320, th = 240, cols = 0, interval_ms = 1000, c;
  int focus_seat = 0, fw = FOCUS_W, fh = FOCUS_H, window = 0, out_set = 0;
  double duration = 0, refresh_hz = 15;
  verr_t err = {{0}};
  int domain = vdds_env_domain(&err);
  if (domain < 0) {
    fprintf(stderr, "viscera-dashboard: %s\n", err.msg);
    return 2;
  }
  while ((c = getopt_long(argc, argv, "", opts, NULL)) != -1) {
    switch (c) {
    case 'p':
      prefix = optarg;
      break;
    case 'n':
      nseats = atoi(optarg);
      break;
    case 'f':
      first = atoi(optarg);
      break;
    case 't':
      if (parse_size(optarg, &tw, &th, 64, 48, 1024)) {
        fprintf(stderr, "viscera-dashboard: --tile '%s': expected WxH, 64x48 to 1024x1024\n", optarg);
        return 2;
      }
      break;
    case 'c':
      cols = atoi(optarg);
      break;
    case 'o':
      out = optarg;
      out_set = 1;
      break;
    case 'i':
      interval_ms = atoi(optarg);
      break;
    case 'd':
      duration = atof(optarg);
      break;
    case 'F':
      focus_seat = atoi(optarg);
      if (focus_seat < 1 || focus_seat > 99) {
        fprintf(stderr, "viscera-dashboard: --focus '%s': expected a seat number 1..99\n", optarg);
        return 2;
      }
      break;
    case 's':
      if (parse_size(optarg, &fw, &fh, DASH_FOCUS_MIN_W, DASH_FOCUS_MIN_H, 4096)) {
        fprintf(stderr, "viscera-dashboard: --size '%s': expected WxH, %dx%d to 4096x4096\n", optarg, DASH_FOCUS_MIN_W,
                DASH_FOCUS_MIN_H);
        return 2;
      }
      break;
    case 'W':
      window = 1;
      break;
    case 'r':
      refresh_hz = atof(optarg);
      break;
    case 'S':
      script = optarg;
      break;
    case 'D':
      domain = vdds_parse_domain(optarg);
      break;
    case 'h':
      usage(stdout);
      return 0;
    default:
      usage(stderr);
      return 2;
    }
  }
  if (nseats < 1 || nseats > MAX_SEATS || first < 1 || first + nseats - 1 > 99 || interval_ms < 50 || domain < 0 ||
      cols < 0 || !(duration >= 0) || strlen(prefix) > 100 || !(refresh_hz >= 1 && refresh_hz <= 60)) {
    fprintf(stderr,
            "viscera-dashboard: bad option value (seats 1..%d within seat numbers 1..99, interval >= 50 ms, "
            "refresh 1..60 Hz)\n",
            MAX_SEATS);
    usage(stderr);
    return 2;
  }
  if (focus_seat && (focus_seat < first || focus_seat >= first + nseats)) {
    fprintf(stderr, "viscera-dashboard: --focus %d: not one of the seats %d..%d\n", focus_seat, first,
            first + nseats - 1);
    return 2;
  }
  if ((script || refresh_hz != 15) && !window) {
    fprintf(stderr, "viscera-dashboard: --script-input and --refresh-hz need --window\n");
    return 2;
  }
#ifndef VISCERA_HAVE_WINDOW
  if (window) {
    fprintf(stderr, "viscera-dashboard: --window: this build has no window mode (SDL2 not found at build time or "
                    "VISCERA_BUILD_WINDOW=OFF); the PNG output needs none\n");
    return 2;
  }
#endif
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
                 "client_lost,focused\n");
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
  int frame = 0;
  while (!g_stop) {
    uint64_t now_ns = vtime_mono_ns();
    double now = (double)(now_ns - t0) * 1e-9;
    if (duration > 0 && now >= duration) break;
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
        fprintf(csv, "%d,%.3f,%s,%d,%.4f,%.4f,%s,%u,%u,%u,%d,%d\n", frame, now, s->partition, s->sv.have_scene, f,
                s->peak, seat_level_name(s->alert), s->crossings[0], s->crossings[1], s->crossings[2], s->client_lost,
                i == focused);
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
