/* SPDX-License-Identifier: Apache-2.0 */
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
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "dash_draw.h"
#include "dash_run.h"
#include "dds/vdds.h"

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
          "  --domain N          DDS domain id (default: $VISCERA_DOMAIN or 0)\n" CLI_HELP_INSECURE
          "  --help              this text\n"
          "  --version           print the version and exit\n"
          "window keys: 1-9 or a click on a tile: focus that seat; Tab / Shift+Tab: next / previous\n"
          "  seat; Esc or a click: back to the grid; Q or closing the window: quit\n"
          "Exit status: 0 done (--duration, Q or SIGINT/SIGTERM), 1 DDS, window or output error,\n"
          "2 usage error.\n",
          MAX_SEATS, FOCUS_W, FOCUS_H);
}

static int parse_size(const char *s, int *w, int *h, int minw, int minh, int max) {
  return sscanf(s, "%dx%d", w, h) == 2 && *w >= minw && *h >= minh && *w <= max && *h <= max ? 0 : -1;
}

enum {
  OPT_PREFIX = 256,
  OPT_SEATS,
  OPT_FIRST,
  OPT_TILE,
  OPT_COLS,
  OPT_OUT,
  OPT_INTERVAL,
  OPT_DURATION,
  OPT_FOCUS,
  OPT_SIZE,
  OPT_WINDOW,
  OPT_REFRESH,
  OPT_SCRIPT,
};

static int on_option(void *ctx, int code, const char *optarg) {
  dash_options_t *o = ctx;
  switch (code) {
  case OPT_PREFIX:
    o->prefix = optarg;
    return 0;
  case OPT_SEATS:
    o->nseats = atoi(optarg);
    return 0;
  case OPT_FIRST:
    o->first = atoi(optarg);
    return 0;
  case OPT_TILE:
    if (parse_size(optarg, &o->tw, &o->th, 64, 48, 1024)) {
      fprintf(stderr, "viscera-dashboard: --tile '%s': expected WxH, 64x48 to 1024x1024\n", optarg);
      return 2;
    }
    return 0;
  case OPT_COLS:
    o->cols = atoi(optarg);
    return 0;
  case OPT_OUT:
    o->out = optarg;
    o->out_set = 1;
    return 0;
  case OPT_INTERVAL:
    o->interval_ms = atoi(optarg);
    return 0;
  case OPT_DURATION:
    o->duration = atof(optarg);
    return 0;
  case OPT_FOCUS:
    o->focus_seat = atoi(optarg);
    if (o->focus_seat < 1 || o->focus_seat > 99) {
      fprintf(stderr, "viscera-dashboard: --focus '%s': expected a seat number 1..99\n", optarg);
      return 2;
    }
    return 0;
  case OPT_SIZE:
    if (parse_size(optarg, &o->fw, &o->fh, DASH_FOCUS_MIN_W, DASH_FOCUS_MIN_H, 4096)) {
      fprintf(stderr, "viscera-dashboard: --size '%s': expected WxH, %dx%d to 4096x4096\n", optarg, DASH_FOCUS_MIN_W,
              DASH_FOCUS_MIN_H);
      return 2;
    }
    return 0;
  case OPT_WINDOW:
    o->window = 1;
    return 0;
  case OPT_REFRESH:
    o->refresh_hz = atof(optarg);
    return 0;
  case OPT_SCRIPT:
    o->script = optarg;
    return 0;
  }
  return 0; /* not reached: cli_parse passes only the codes above */
}

/* The values together; 0, or 2 after a message. */
static int check_options(const dash_options_t *o) {
  const char *prefix = o->prefix, *script = o->script;
  int nseats = o->nseats, first = o->first, interval_ms = o->interval_ms, domain = o->domain, cols = o->cols;
  int focus_seat = o->focus_seat, window = o->window;
  double duration = o->duration, refresh_hz = o->refresh_hz;
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
  return 0;
}

int main(int argc, char **argv) {
  vdds_set_role("dashboard"); /* announced in the participant USER_DATA */
  static const struct option opts[] = {{"prefix", required_argument, 0, OPT_PREFIX},
                                       {"seats", required_argument, 0, OPT_SEATS},
                                       {"first", required_argument, 0, OPT_FIRST},
                                       {"tile", required_argument, 0, OPT_TILE},
                                       {"cols", required_argument, 0, OPT_COLS},
                                       {"out", required_argument, 0, OPT_OUT},
                                       {"interval-ms", required_argument, 0, OPT_INTERVAL},
                                       {"duration", required_argument, 0, OPT_DURATION},
                                       {"focus", required_argument, 0, OPT_FOCUS},
                                       {"size", required_argument, 0, OPT_SIZE},
                                       {"window", no_argument, 0, OPT_WINDOW},
                                       {"refresh-hz", required_argument, 0, OPT_REFRESH},
                                       {"script-input", required_argument, 0, OPT_SCRIPT},
                                       {0, 0, 0, 0}};
  const cli_spec_t spec = {.program = "viscera-dashboard",
                           .common = CLI_DOMAIN | CLI_DOMAIN_ENV,
                           .options = opts,
                           .option = on_option,
                           .shortopts = "h",
                           .usage = usage};
  dash_options_t o = {.prefix = "lab",
                      .out = "dashboard",
                      .nseats = 4,
                      .first = 1,
                      .tw = 320,
                      .th = 240,
                      .interval_ms = 1000,
                      .fw = FOCUS_W,
                      .fh = FOCUS_H,
                      .refresh_hz = 15};
  cli_common_t common = {0};
  int rc = cli_parse(&spec, argc, argv, &common, &o);
  if (rc != CLI_RUN) return rc;
  o.domain = common.domain;
  if (check_options(&o)) return 2;
  return dash_run(&o);
}
