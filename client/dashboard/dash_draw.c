/* SPDX-License-Identifier: Apache-2.0 */
#include "dash_draw.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "view/scene_draw.h"
#include "viscera.h"

#define CURVE_R 0.55
#define CURVE_G 0.85
#define CURVE_B 1.0

int dash_open(dash_t *d, seat_t *seats, int nseats, int cols, int tw, int th, verr_t *err) {
  memset(d, 0, sizeof *d);
  d->seats = seats;
  d->nseats = nseats;
  d->cols = cols;
  d->rows = (nseats + cols - 1) / cols;
  d->tw = tw;
  d->th = th;
  return render_open(&d->r_tile, tw, th, 2, err);
}

void dash_close(dash_t *d) {
  if (d->r_tile) render_close(d->r_tile);
  if (d->r_focus) render_close(d->r_focus);
  d->r_tile = d->r_focus = NULL;
}

void dash_grid_size(const dash_t *d, int *w, int *h) {
  *w = d->cols * d->tw;
  *h = d->rows * (DASH_HEADER_H + d->th + DASH_GRAPH_H);
}

void dash_update(dash_t *d) {
  for (int i = 0; i < d->nseats; i++) {
    seat_t *s = &d->seats[i];
    double bmin[3], bmax[3];
    if (!s->have_camera && scene_view_complete(&s->sv) && scene_view_key_bounds(&s->sv, bmin, bmax) == 0 &&
        camera_frame(&s->cam, bmin, bmax, d->tw, d->th) == 0)
      s->have_camera = 1;
  }
}

/* Copies the renderer's RGB rows (bottom-up) into cr's image surface at
 * (x0, y0), clipped to the surface. */
static void blit(cairo_t *cr, const uint8_t *rgb, int w, int h, int x0, int y0) {
  cairo_surface_t *dst = cairo_get_target(cr);
  cairo_surface_flush(dst);
  unsigned char *d = cairo_image_surface_get_data(dst);
  int stride = cairo_image_surface_get_stride(dst);
  int dw = cairo_image_surface_get_width(dst), dh = cairo_image_surface_get_height(dst);
  for (int y = 0; y < h; y++) {
    if (y0 + y < 0 || y0 + y >= dh) continue;
    const uint8_t *src = rgb + (size_t)(h - 1 - y) * w * 3;
    uint32_t *row = (uint32_t *)(d + (size_t)(y0 + y) * stride);
    for (int x = 0; x < w; x++)
      if (x0 + x >= 0 && x0 + x < dw)
        row[x0 + x] = 0xff000000u | (uint32_t)src[3 * x] << 16 | (uint32_t)src[3 * x + 1] << 8 | src[3 * x + 2];
  }
  cairo_surface_mark_dirty(dst);
}

static void text(cairo_t *cr, double x, double y, double size, const char *s) {
  cairo_set_font_size(cr, size);
  cairo_move_to(cr, x, y);
  cairo_show_text(cr, s);
}

/* Shows s at (x, y), cut with "..." to at most maxw pixels. */
static void text_fit(cairo_t *cr, double x, double y, double size, const char *s, double maxw) {
  char buf[256];
  snprintf(buf, sizeof buf, "%s", s);
  cairo_set_font_size(cr, size);
  cairo_text_extents_t te;
  if (size < 0) { /* -size: shrink down to 10 px before cutting */
    cairo_set_font_size(cr, -size);
    cairo_text_extents(cr, buf, &te);
    size = te.x_advance > maxw && maxw > 0 ? fmax(10, -size * maxw / te.x_advance) : -size;
    cairo_set_font_size(cr, size);
  }
  size_t n = strlen(buf);
  for (;;) {
    cairo_text_extents(cr, buf, &te);
    if (te.x_advance <= maxw || n <= 3) break;
    n--;
    memcpy(buf + n - 3, "...", 4);
  }
  cairo_move_to(cr, x, y);
  cairo_show_text(cr, buf);
}

static void set_rgb(cairo_t *cr, const double c[3]) { cairo_set_source_rgb(cr, c[0], c[1], c[2]); }

static void level_rgb(seat_alert_t a, double c[3]) { seat_level_rgb(a, c); }

/* Force over the last DASH_GRAPH_SECONDS with the threshold lines. The
 * detailed form (focus view) adds axes in N and s and names the lines. */
static void draw_graph(cairo_t *cr, const seat_t *s, double x, double y, double w, double h, int detailed) {
  float st, mpf, sft, maxf;
  seat_force(s, &st, &mpf, &sft, &maxf);
  uint64_t n = s->nhist < SEAT_HISTORY ? s->nhist : SEAT_HISTORY;
  size_t span = (size_t)(DASH_GRAPH_SECONDS * DASH_SAMPLE_HZ);
  if (n > span) n = span;
  double shown_peak = 0;
  for (uint64_t i = 0; i < n; i++) shown_peak = fmax(shown_peak, s->history[(s->nhist - n + i) % SEAT_HISTORY]);
  double top = fmax(fmax(sft, mpf) * 1.25, fmax(shown_peak * 1.1, 0.5));
  cairo_set_source_rgb(cr, 0.12, 0.12, 0.14);
  cairo_rectangle(cr, x, y, w, h);
  cairo_fill(cr);
  if (detailed) {
    /* Gridlines every 0.25, 0.5 or 1 N (at most about 6), every 5 s. */
    double step = top / 6 > 0.5 ? 1.0 : top / 6 > 0.25 ? 0.5 : 0.25;
    char lab[32];
    cairo_set_line_width(cr, 1);
    for (double v = 0; v <= top + 1e-9; v += step) {
      double ly = y + h - v / top * h;
      cairo_set_source_rgb(cr, 0.22, 0.22, 0.25);
      cairo_move_to(cr, x, ly);
      cairo_line_to(cr, x + w, ly);
      cairo_stroke(cr);
      cairo_set_source_rgb(cr, 0.7, 0.7, 0.75);
      snprintf(lab, sizeof lab, "%.2g N", v);
      text(cr, x - 42, ly + 4, 11, lab);
    }
    for (int k = 0; k <= (int)DASH_GRAPH_SECONDS; k += 5) {
      double lx = x + w - k / DASH_GRAPH_SECONDS * w;
      cairo_set_source_rgb(cr, 0.22, 0.22, 0.25);
      cairo_move_to(cr, lx, y);
      cairo_line_to(cr, lx, y + h);
      cairo_stroke(cr);
      cairo_set_source_rgb(cr, 0.7, 0.7, 0.75);
      if (k)
        snprintf(lab, sizeof lab, "-%d s", k);
      else
        snprintf(lab, sizeof lab, "now");
      text(cr, lx - (k ? 14 : 10), y + h + 14, 11, lab);
    }
  }
  const float lv[3] = {st, mpf, sft};
  static const char *const names[3] = {"ST", "MPF", "SFT"};
  cairo_set_line_width(cr, detailed ? 1.5 : 1);
  for (int k = 0; k < 3; k++) {
    if (!(lv[k] > 0)) continue;
    double ly = y + h - lv[k] / top * h, c[3];
    level_rgb((seat_alert_t)(k + 1), c);
    set_rgb(cr, c);
    cairo_move_to(cr, x, ly);
    cairo_line_to(cr, x + w, ly);
    cairo_stroke(cr);
    if (detailed) {
      char lab[32];
      snprintf(lab, sizeof lab, "%s %.2f N", names[k], lv[k]);
      text(cr, x + w + 6, ly + 4, 11, lab);
    }
  }
  cairo_set_source_rgb(cr, CURVE_R, CURVE_G, CURVE_B);
  cairo_set_line_width(cr, detailed ? 2.5 : 1.5);
  for (uint64_t i = 0; i < n; i++) {
    float f = s->history[(s->nhist - n + i) % SEAT_HISTORY];
    double px = x + w - (double)(n - 1 - i) / (double)span * w, py = y + h - fmin(f / top, 1.0) * h;
    if (i == 0)
      cairo_move_to(cr, px, py);
    else
      cairo_line_to(cr, px, py);
  }
  cairo_stroke(cr);
  if (!detailed) {
    char buf[96];
    cairo_set_source_rgb(cr, 0.8, 0.8, 0.85);
    snprintf(buf, sizeof buf, "%.0f s   peak %.2f N   above ST x%u MPF x%u SFT x%u", DASH_GRAPH_SECONDS, s->peak,
             s->crossings[0], s->crossings[1], s->crossings[2]);
    text(cr, x + 4, y + 12, 10, buf);
  }
}

static void draw_tile(dash_t *d, int i, cairo_t *cr, int x, int y, verr_t *err) {
  seat_t *s = &d->seats[i];
  int tw = d->tw, th = d->th;
  if (s->have_camera) {
    const uint8_t *img = scene_draw(d->r_tile, &s->cam, &s->sv, 1, err);
    if (img) blit(cr, img, tw, th, x, y + DASH_HEADER_H);
  } else {
    cairo_set_source_rgb(cr, 0.6, 0.6, 0.65);
    text(cr, x + 12, y + DASH_HEADER_H + th / 2.0, 14, s->sv.have_scene ? "waiting for the organs" : "no server");
  }
  draw_graph(cr, s, x + 2, y + DASH_HEADER_H + th, tw - 4, DASH_GRAPH_H - 4, 0);
  float st, mpf, sft, maxf;
  double f = seat_force(s, &st, &mpf, &sft, &maxf);
  char head[200];
  snprintf(head, sizeof head, "%.60s  %.64s  %.2f N", s->partition, s->sv.have_scene ? s->sv.scene_name : "-", f);
  cairo_set_source_rgb(cr, 0.9, 0.9, 0.92);
  text_fit(cr, x + 6, y + 15, 12, head, tw - 12);
  if (s->client_lost || s->client_left) {
    /* On the scene, in the focus view's colours: at the end of the header
     * it was cut off on a tile of the default size. */
    if (s->client_lost)
      cairo_set_source_rgb(cr, 0.95, 0.35, 0.3);
    else
      cairo_set_source_rgb(cr, 0.6, 0.6, 0.6);
    text(cr, x + 8, y + DASH_HEADER_H + 22, 15, s->client_lost ? "trainee lost" : "trainee left");
  }
  if (s->paused) { /* the instructor's own pause, so the seat's stillness is not mistaken for idleness */
    cairo_set_source_rgb(cr, 0.45, 0.7, 1.0);
    text(cr, x + 8, y + DASH_HEADER_H + (s->client_lost || s->client_left ? 42 : 22), 15, "paused");
  }
  if (s->alert != SEAT_OK) {
    /* The frame an instructor notices from across the room. */
    double c[3];
    level_rgb(s->alert, c);
    set_rgb(cr, c);
    cairo_set_line_width(cr, 5);
    cairo_rectangle(cr, x + 2.5, y + 2.5, tw - 5, DASH_HEADER_H + th + DASH_GRAPH_H - 5);
    cairo_stroke(cr);
    char a[32];
    snprintf(a, sizeof a, "above %s", seat_level_name(s->alert));
    text(cr, x + tw - 110, y + DASH_HEADER_H + 22, 16, a);
  }
}

void dash_draw_grid(dash_t *d, cairo_t *cr, int x0, int y0, verr_t *err) {
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  for (int i = 0; i < d->nseats; i++)
    draw_tile(d, i, cr, x0 + (i % d->cols) * d->tw, y0 + (i / d->cols) * (DASH_HEADER_H + d->th + DASH_GRAPH_H), err);
}

int dash_tile_at(const dash_t *d, int x0, int y0, int x, int y) {
  int th = DASH_HEADER_H + d->th + DASH_GRAPH_H;
  if (x < x0 || y < y0) return -1;
  int c = (x - x0) / d->tw, r = (y - y0) / th;
  if (c >= d->cols || r >= d->rows) return -1;
  int i = r * d->cols + c;
  return i < d->nseats ? i : -1;
}

void dash_focus_badge_rect(int w, int h, int *x, int *y, int *bw, int *bh) {
  (void)h;
  *bw = 230;
  *bh = 34;
  *x = w - DASH_FOCUS_MARGIN - *bw;
  *y = (DASH_FOCUS_HEADER_H - *bh) / 2;
}

/* The focus view's scene at sw x sh: its own renderer and a camera framed
 * for that size (the tile's camera has the tile's aspect). */
static int draw_focus_scene(dash_t *d, seat_t *s, cairo_t *cr, int x, int y, int sw, int sh, verr_t *err) {
  cairo_set_source_rgb(cr, 0.1, 0.1, 0.11);
  cairo_rectangle(cr, x, y, sw, sh);
  cairo_fill(cr);
  double bmin[3], bmax[3];
  camera_t cam;
  if (!scene_view_complete(&s->sv) || scene_view_key_bounds(&s->sv, bmin, bmax) ||
      camera_frame(&cam, bmin, bmax, sw, sh)) {
    cairo_set_source_rgb(cr, 0.6, 0.6, 0.65);
    text(cr, x + 16, y + sh / 2.0, 18, s->sv.have_scene ? "waiting for the organs" : "no server on this seat");
    return 0;
  }
  if (!d->r_focus || d->fw != sw || d->fh != sh) {
    if (d->r_focus) render_close(d->r_focus);
    d->r_focus = NULL;
    if (render_open(&d->r_focus, sw, sh, 2, err)) return -1;
    d->fw = sw, d->fh = sh;
  }
  const uint8_t *img = scene_draw(d->r_focus, &cam, &s->sv, 1, err);
  if (!img) return -1;
  blit(cr, img, sw, sh, x, y);
  return 0;
}

/* A label in grey and its value in white (or colour c) on one line. */
static void field(cairo_t *cr, double x, double y, const char *label, const char *value, const double *c) {
  cairo_set_source_rgb(cr, 0.62, 0.62, 0.68);
  text(cr, x, y, 14, label);
  if (c)
    set_rgb(cr, c);
  else
    cairo_set_source_rgb(cr, 0.93, 0.93, 0.95);
  text(cr, x + 110, y, 14, value);
}

/* "ST 4.2 s   MPF 3.1 s   SFT 0.0 s", each in its level's colour, in a
 * smaller font when 14 px would not fit in maxw. */
static void three_levels(cairo_t *cr, double x, double y, const double v[3], const char *fmt, double maxw) {
  static const char *const names[3] = {"ST", "MPF", "SFT"};
  char b[3][48];
  double wsum = 0, size = 14, gap = 16;
  cairo_set_font_size(cr, size);
  for (int k = 0; k < 3; k++) {
    snprintf(b[k], sizeof b[k], fmt, names[k], v[k]);
    cairo_text_extents_t te;
    cairo_text_extents(cr, b[k], &te);
    wsum += te.x_advance + (k < 2 ? gap : 0);
  }
  if (wsum > maxw && maxw > 0) size = fmax(8, size * maxw / wsum), gap *= size / 14;
  for (int k = 0; k < 3; k++) {
    double c[3];
    level_rgb((seat_alert_t)(k + 1), c);
    set_rgb(cr, c);
    cairo_set_font_size(cr, size);
    cairo_text_extents_t te;
    cairo_text_extents(cr, b[k], &te);
    text(cr, x, y, size, b[k]);
    x += te.x_advance + gap;
  }
}

static void draw_panel(const seat_t *s, cairo_t *cr, double x, double y, double pw, double ph) {
  float st, mpf, sft, maxf;
  double f = seat_force(s, &st, &mpf, &sft, &maxf);
  int p = seat_tool(s);
  seat_alert_t lv = seat_level_of(f, st, mpf, sft);
  /* The level's colour only in contact, as the badge: no contact is grey. */
  double c[3] = {0.6, 0.6, 0.65};
  if (p >= 0 && s->sv.tools[p].have_contact && s->sv.tools[p].in_contact) level_rgb(lv, c);
  char b[200];
  double ly = y + 18;
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_source_rgb(cr, 0.62, 0.62, 0.68);
  text(cr, x, ly, 14, "Force now");
  set_rgb(cr, c);
  snprintf(b, sizeof b, "%.2f N", f);
  text(cr, x + 110, ly + 4, 26, b);
  ly += 34;
  /* The server's measures when it publishes them (simulated time, every
   * step); otherwise what this dashboard saw at its own sample rate. */
  const seat_tool_measures_t *m = p >= 0 && s->measures[p].have ? &s->measures[p] : NULL;
  snprintf(b, sizeof b, "%.2f N%s", m ? fmax(m->peak, s->peak) : s->peak, m ? "" : "  (seen here)");
  field(cr, x, ly, "Peak", b, NULL);
  ly += 22;
  cairo_set_source_rgb(cr, 0.62, 0.62, 0.68);
  text(cr, x, ly, 14, "Time above");
  three_levels(cr, x + 110, ly, m ? m->above : s->above_seen, "%s %.1f s", pw - 110);
  ly += 22;
  const double thr[3] = {st, mpf, sft};
  cairo_set_source_rgb(cr, 0.62, 0.62, 0.68);
  text(cr, x, ly, 14, "Thresholds");
  if (p >= 0 && (st > 0 || mpf > 0 || sft > 0))
    three_levels(cr, x + 110, ly, thr, "%s %.2f N", pw - 110);
  else {
    cairo_set_source_rgb(cr, 0.93, 0.93, 0.95);
    text(cr, x + 110, ly, 14, p >= 0 ? "none set" : "-");
  }
  ly += 22;
  snprintf(b, sizeof b, "ST x%u   MPF x%u   SFT x%u", s->crossings[0], s->crossings[1], s->crossings[2]);
  field(cr, x, ly, "Crossed up", b, NULL);
  ly += 28;
  /* Who drives and who guides the trainee's tool (ToolRole). */
  char tname[72], role[160];
  if (p >= 0) {
    seat_text_clean(tname, sizeof tname, s->sv.tools[p].name);
    const seat_role_t *r = &s->roles[p];
    seat_role_text(role, sizeof role, r->have, r->owner, r->guide, r->authority);
    snprintf(b, sizeof b, "%d %.40s", p, tname);
    field(cr, x, ly, "Tool", b, NULL);
    ly += 22;
    cairo_set_source_rgb(cr, 0.62, 0.62, 0.68);
    text(cr, x, ly, 14, "Driven by");
    cairo_set_source_rgb(cr, 0.93, 0.93, 0.95);
    text_fit(cr, x + 110, ly, -14, role, pw - 110); /* shrunk rather than cut: the role matters */
  } else {
    field(cr, x, ly, "Tool", s->sv.have_scene ? "none in the scene" : "-", NULL);
    ly += 22;
  }
  ly += 30;
  cairo_set_source_rgb(cr, 0.62, 0.62, 0.68);
  text(cr, x, ly, 14, "Seat events (simulated time)");
  ly += 6;
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  for (unsigned k = 0; ly + 18 <= y + ph; k++) {
    const seat_event_t *e = seat_event(s, k);
    if (!e) {
      if (k == 0) {
        cairo_set_source_rgb(cr, 0.55, 0.55, 0.6);
        text(cr, x, ly + 18, 13, "none yet");
      }
      break;
    }
    ly += 18;
    /* Crossings in their level's colour, a lost client in red. */
    double ec[3] = {0.85, 0.85, 0.88};
    if (e->kind == viscera_EVENT_THRESHOLD_CROSSED_UP)
      level_rgb(strncmp(e->text, "SFT", 3) == 0   ? SEAT_ABOVE_SFT
                : strncmp(e->text, "MPF", 3) == 0 ? SEAT_ABOVE_MPF
                                                  : SEAT_ABOVE_ST,
                ec);
    else if (e->kind == viscera_EVENT_CLIENT_LOST && strstr(e->text, "client left"))
      ec[0] = ec[1] = ec[2] = 0.6; /* a clean exit: grey, not an alarm */
    else if (e->kind == viscera_EVENT_CLIENT_LOST)
      ec[0] = 0.95, ec[1] = 0.35, ec[2] = 0.3;
    /* The server's texts mostly say what happened ("MPF crossed up: ..."):
     * the kind's label only where they do not. */
    const char *label = seat_event_label(e->kind);
    if (strstr(e->text, label))
      snprintf(b, sizeof b, "%7.1f s  %s", e->sim_s, e->text);
    else
      snprintf(b, sizeof b, "%7.1f s  %s: %s", e->sim_s, label, e->text);
    set_rgb(cr, ec);
    text_fit(cr, x, ly, 13, b, pw);
  }
}

int dash_draw_focus(dash_t *d, int i, cairo_t *cr, int w, int h, verr_t *err) {
  seat_t *s = &d->seats[i];
  const int M = DASH_FOCUS_MARGIN;
  cairo_set_source_rgb(cr, 0.07, 0.07, 0.08);
  cairo_paint(cr);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  /* Title band: which seat, and the current level as a badge. */
  char b[200], scene[72];
  seat_text_clean(scene, sizeof scene, s->sv.have_scene ? s->sv.scene_name : "no server");
  snprintf(b, sizeof b, "%.100s  -  %s", s->partition, scene);
  cairo_set_source_rgb(cr, 0.93, 0.93, 0.95);
  int bx, by, bw, bh;
  dash_focus_badge_rect(w, h, &bx, &by, &bw, &bh);
  if (s->client_lost || s->client_left) {
    /* Next to the seat's name, where the instructor looks first. */
    cairo_set_font_size(cr, 20);
    cairo_text_extents_t tt;
    cairo_text_extents(cr, b, &tt);
    double room = bx - 2 * M - 190;
    text_fit(cr, M, 31, 20, b, room);
    if (s->client_lost)
      cairo_set_source_rgb(cr, 0.95, 0.35, 0.3);
    else
      cairo_set_source_rgb(cr, 0.6, 0.6, 0.6);
    text(cr, M + fmin(tt.x_advance, room) + 14, 31, 15,
         s->client_lost ? "trainee's client lost" : "trainee's client left");
  } else {
    text_fit(cr, M, 31, 20, b, bx - 2 * M);
  }
  float st, mpf, sft, maxf;
  double f = seat_force(s, &st, &mpf, &sft, &maxf);
  int p = seat_tool(s);
  int contact = p >= 0 && s->sv.tools[p].have_contact && s->sv.tools[p].in_contact;
  seat_alert_t lv = seat_level_of(f, st, mpf, sft);
  double c[3] = {0.35, 0.35, 0.4};
  if (contact) level_rgb(lv, c);
  set_rgb(cr, c);
  cairo_rectangle(cr, bx, by, bw, bh);
  cairo_fill(cr);
  static const char *const badge[4] = {"BELOW ST", "ABOVE ST", "ABOVE MPF", "ABOVE SFT"};
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_set_font_size(cr, 17);
  const char *bt = contact                                                               ? badge[lv]
                   : p >= 0 && (s->sv.tools[p].have_pose || s->sv.tools[p].have_contact) ? "NO CONTACT"
                   : p >= 0                                                              ? "NOT DRIVEN"
                                                                                         : "NO TOOL";
  cairo_text_extents_t te;
  cairo_text_extents(cr, bt, &te);
  text(cr, bx + (bw - te.x_advance) / 2, by + bh / 2.0 + 6, 17, bt);

  /* Graph along the bottom, scene left, numbers right. */
  int gh = (int)fmax(140, (h - DASH_FOCUS_HEADER_H) * 0.3);
  int gx = M + 46, gw = w - gx - M - 78, gy = h - M - 16 - gh;
  cairo_set_source_rgb(cr, 0.62, 0.62, 0.68);
  text(cr, gx, gy - 8, 13, "Contact force, last 30 s");
  draw_graph(cr, s, gx, gy, gw, gh, 1);
  int top = DASH_FOCUS_HEADER_H + 6, body = gy - 26 - top;
  int sw = (int)((w - 3 * M) * 0.56), sh = body;
  int rc = draw_focus_scene(d, s, cr, M, top, sw, sh, err);
  int px = M + sw + M;
  draw_panel(s, cr, px, top, w - px - M, body);
  if (s->alert != SEAT_OK) {
    /* As on the tile: a recent crossing frames the whole view. */
    level_rgb(s->alert, c);
    set_rgb(cr, c);
    cairo_set_line_width(cr, 6);
    cairo_rectangle(cr, 3, 3, w - 6, h - 6);
    cairo_stroke(cr);
  }
  return rc;
}
