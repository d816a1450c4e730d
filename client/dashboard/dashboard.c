/* viscera-dashboard: the instructor's grid of a lab's seats (issue 7).
 *
 * One tile per seat (partition PREFIX/seatNN): the organ and tool as the
 * viewer draws them, the trainee's contact force over the last 30 s against
 * the seat's palpation thresholds, and an alert frame (orange above ST, red
 * above MPF or SFT) for SEAT_ALERT_HOLD_S after the server reports a
 * crossing. Seats without a server say so. Writes the grid as PNG frames at
 * an interval and a CSV row per seat and frame, so a session's alerts can be
 * checked afterwards. The window version of this view waits for the window
 * viewer. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cairo.h>

#include "plot_cleanup.h"
#include "render.h"
#include "scene_draw.h"
#include "seat.h"
#include "vsignal.h"
#include "vtime.h"
#include "vdds_ident.h"

#define MAX_SEATS 32
#define HEADER_H 22
#define GRAPH_H 70
#define GRAPH_SECONDS 30.0
#define SAMPLE_HZ 10.0

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
          "  --domain N          DDS domain id (default: $VISCERA_DOMAIN or 0)\n"
          "  --help              this text\n",
          MAX_SEATS);
}

static const char *alert_name(seat_alert_t a) {
  static const char *const n[] = {"ok", "ST", "MPF", "SFT"};
  return n[a];
}

/* Copies the renderer's RGB rows (bottom-up) into the cairo surface at (x0, y0). */
static void blit(cairo_surface_t *dst, const uint8_t *rgb, int w, int h, int x0, int y0) {
  cairo_surface_flush(dst);
  unsigned char *d = cairo_image_surface_get_data(dst);
  int stride = cairo_image_surface_get_stride(dst);
  for (int y = 0; y < h; y++) {
    const uint8_t *src = rgb + (size_t)(h - 1 - y) * w * 3;
    uint32_t *row = (uint32_t *)(d + (size_t)(y0 + y) * stride) + x0;
    for (int x = 0; x < w; x++)
      row[x] = 0xff000000u | (uint32_t)src[3 * x] << 16 | (uint32_t)src[3 * x + 1] << 8 | src[3 * x + 2];
  }
  cairo_surface_mark_dirty(dst);
}

static void text(cairo_t *cr, double x, double y, double size, const char *s) {
  cairo_set_font_size(cr, size);
  cairo_move_to(cr, x, y);
  cairo_show_text(cr, s);
}

/* Force over the last GRAPH_SECONDS with the threshold lines. */
static void draw_graph(cairo_t *cr, const seat_t *s, double x, double y, double w, double h) {
  float st, mpf, sft, maxf;
  seat_force(s, &st, &mpf, &sft, &maxf);
  double top = fmax(fmax(sft, mpf) * 1.25, fmax(s->peak * 1.1, 0.5));
  cairo_set_source_rgb(cr, 0.12, 0.12, 0.14);
  cairo_rectangle(cr, x, y, w, h);
  cairo_fill(cr);
  const float lv[3] = {st, mpf, sft};
  const double col[3][3] = {{0.95, 0.6, 0.1}, {0.9, 0.2, 0.2}, {0.7, 0.1, 0.6}};
  cairo_set_line_width(cr, 1);
  for (int k = 0; k < 3; k++) {
    if (!(lv[k] > 0)) continue;
    double ly = y + h - lv[k] / top * h;
    cairo_set_source_rgb(cr, col[k][0], col[k][1], col[k][2]);
    cairo_move_to(cr, x, ly);
    cairo_line_to(cr, x + w, ly);
    cairo_stroke(cr);
  }
  uint64_t n = s->nhist < SEAT_HISTORY ? s->nhist : SEAT_HISTORY;
  size_t span = (size_t)(GRAPH_SECONDS * SAMPLE_HZ);
  if (n > span) n = span;
  cairo_set_source_rgb(cr, 0.55, 0.85, 1.0);
  cairo_set_line_width(cr, 1.5);
  for (uint64_t i = 0; i < n; i++) {
    float f = s->history[(s->nhist - n + i) % SEAT_HISTORY];
    double px = x + w - (double)(n - 1 - i) / (double)span * w, py = y + h - fmin(f / top, 1.0) * h;
    if (i == 0)
      cairo_move_to(cr, px, py);
    else
      cairo_line_to(cr, px, py);
  }
  cairo_stroke(cr);
  char buf[96];
  cairo_set_source_rgb(cr, 0.8, 0.8, 0.85);
  snprintf(buf, sizeof buf, "%.0f s   peak %.2f N   above ST x%u MPF x%u SFT x%u", GRAPH_SECONDS, s->peak,
           s->crossings[0], s->crossings[1], s->crossings[2]);
  text(cr, x + 4, y + 12, 10, buf);
}

static int parse_size(const char *s, int *w, int *h) {
  return sscanf(s, "%dx%d", w, h) == 2 && *w >= 64 && *h >= 48 && *w <= 1024 && *h <= 1024 ? 0 : -1;
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
                                       {"domain", required_argument, 0, 'D'},
                                       {"help", no_argument, 0, 'h'},
                                       {0, 0, 0, 0}};
  const char *prefix = "lab", *out = "dashboard";
  int nseats = 4, first = 1, tw = 320, th = 240, cols = 0, interval_ms = 1000, c;
  double duration = 0;
  verr_t err;
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
      if (parse_size(optarg, &tw, &th)) {
        fprintf(stderr, "viscera-dashboard: --tile '%s': expected WxH, 64x48 to 1024x1024\n", optarg);
        return 2;
      }
      break;
    case 'c':
      cols = atoi(optarg);
      break;
    case 'o':
      out = optarg;
      break;
    case 'i':
      interval_ms = atoi(optarg);
      break;
    case 'd':
      duration = atof(optarg);
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
      cols < 0 || !(duration >= 0) || strlen(prefix) > 100) {
    fprintf(stderr, "viscera-dashboard: bad option value (seats 1..%d within seat numbers 1..99, interval >= 50 ms)\n",
            MAX_SEATS);
    usage(stderr);
    return 2;
  }
  if (cols == 0) cols = (int)ceil(sqrt((double)nseats));
  if (cols > nseats) cols = nseats;
  int rows = (nseats + cols - 1) / cols;
  if (mkdir(out, 0755) && errno != EEXIST) {
    fprintf(stderr, "viscera-dashboard: cannot create %s: %s\n", out, strerror(errno));
    return 1;
  }
  char csv_path[1024];
  snprintf(csv_path, sizeof csv_path, "%s/dashboard.csv", out);
  FILE *csv = fopen(csv_path, "w");
  if (!csv) {
    fprintf(stderr, "viscera-dashboard: cannot write %s: %s\n", csv_path, strerror(errno));
    return 1;
  }
  fprintf(csv,
          "frame,wall_s,seat,have_scene,force_n,peak_n,alert,crossings_st,crossings_mpf,crossings_sft,client_lost\n");

  static seat_t seats[MAX_SEATS];
  int rc = 0, opened = 0;
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
  render_t *r = NULL;
  if (render_open(&r, tw, th, 2, &err)) {
    fprintf(stderr, "viscera-dashboard: %s\n", err.msg);
    rc = 1;
    goto done;
  }
  int W = cols * tw, H = rows * (HEADER_H + th + GRAPH_H);
  cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
  fprintf(stderr, "viscera-dashboard: %d seat(s) %s/seat%02d..seat%02d on domain %d, %dx%d grid, frames to %s\n",
          nseats, prefix, first, first + nseats - 1, domain, cols, rows, out);
  vsignal_on_stop(on_signal, 0);
  uint64_t t0 = vtime_mono_ns(), next_sample = t0, next_frame = t0 + (uint64_t)interval_ms * 1000000ull;
  int frame = 0;
  while (!g_stop) {
    uint64_t now_ns = vtime_mono_ns();
    double now = (double)(now_ns - t0) * 1e-9;
    if (duration > 0 && now >= duration) break;
    for (int i = 0; i < nseats; i++) {
      if (seat_poll(&seats[i], now, &err)) fprintf(stderr, "viscera-dashboard: %s: %s\n", seats[i].partition, err.msg);
      seat_t *s = &seats[i];
      double bmin[3], bmax[3];
      if (!s->have_camera && scene_view_complete(&s->sv) && scene_view_key_bounds(&s->sv, bmin, bmax) == 0 &&
          camera_frame(&s->cam, bmin, bmax, tw, th) == 0)
        s->have_camera = 1;
      seat_sample(s);
    }
    if (now_ns >= next_frame) {
      next_frame += (uint64_t)interval_ms * 1000000ull;
      cairo_t *cr = cairo_create(surf);
      cairo_set_source_rgb(cr, 0.07, 0.07, 0.08);
      cairo_paint(cr);
      cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
      for (int i = 0; i < nseats; i++) {
        seat_t *s = &seats[i];
        int x = (i % cols) * tw, y = (i / cols) * (HEADER_H + th + GRAPH_H);
        if (s->have_camera) {
          const uint8_t *img = scene_draw(r, &s->cam, &s->sv, 1, &err);
          if (img) blit(surf, img, tw, th, x, y + HEADER_H);
        } else {
          cairo_set_source_rgb(cr, 0.6, 0.6, 0.65);
          text(cr, x + 12, y + HEADER_H + th / 2.0, 14, s->sv.have_scene ? "waiting for the organs" : "no server");
        }
        draw_graph(cr, s, x + 2, y + HEADER_H + th, tw - 4, GRAPH_H - 4);
        float st, mpf, sft, maxf;
        double f = seat_force(s, &st, &mpf, &sft, &maxf);
        char head[200];
        snprintf(head, sizeof head, "%.60s  %.64s  %.2f N%s", s->partition, s->sv.have_scene ? s->sv.scene_name : "-", f,
                 s->client_lost ? "  trainee lost" : "");
        cairo_set_source_rgb(cr, 0.9, 0.9, 0.92);
        text(cr, x + 6, y + 15, 12, head);
        if (s->alert != SEAT_OK) {
          /* The frame an instructor notices from across the room. */
          if (s->alert == SEAT_ABOVE_ST)
            cairo_set_source_rgb(cr, 0.95, 0.6, 0.1);
          else
            cairo_set_source_rgb(cr, 0.9, 0.15, 0.15);
          cairo_set_line_width(cr, 5);
          cairo_rectangle(cr, x + 2.5, y + 2.5, tw - 5, HEADER_H + th + GRAPH_H - 5);
          cairo_stroke(cr);
          char a[32];
          snprintf(a, sizeof a, "above %s", alert_name(s->alert));
          text(cr, x + tw - 110, y + HEADER_H + 22, 16, a);
        }
        fprintf(csv, "%d,%.3f,%s,%d,%.4f,%.4f,%s,%u,%u,%u,%d\n", frame, now, s->partition, s->sv.have_scene, f, s->peak,
                alert_name(s->alert), s->crossings[0], s->crossings[1], s->crossings[2], s->client_lost);
      }
      cairo_destroy(cr);
      char png[1100];
      snprintf(png, sizeof png, "%s/dashboard_%05d.png", out, frame++);
      if (cairo_surface_write_to_png(surf, png) != CAIRO_STATUS_SUCCESS)
        fprintf(stderr, "viscera-dashboard: cannot write %s\n", png);
      fflush(csv);
    }
    next_sample += (uint64_t)(1e9 / SAMPLE_HZ);
    vtime_sleep_until(next_sample);
  }
  fprintf(stderr, "viscera-dashboard: %d frame(s) written\n", frame);
  cairo_surface_destroy(surf);
  render_close(r);
done:
  for (int i = 0; i < opened; i++) seat_close(&seats[i]);
  fclose(csv);
  plot_cleanup(); /* cairo's and fontconfig's process caches (LeakSanitizer) */
  return rc;
}
