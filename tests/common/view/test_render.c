/* SPDX-License-Identifier: Apache-2.0 */
/* test_render: the viewer's offscreen renderer, camera projection and PNG
 * writer, on an icosphere built here. Checks what a person would look for:
 * the sphere is drawn where the camera projects it and nowhere else, it is
 * shaded (lit side brighter), a PNG holds exactly the rendered pixels, and a
 * displaced vertex changes the image near its projection only. */
#include <png.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "view/camera.h"
#include "check.h"
#include "view/png_write.h"
#include "view/render.h"

#define W 200
#define H 150

typedef struct sphere {
  size_t nverts, ntris;
  float pos[3 * 2562];
  uint32_t tris[3 * 5120];
} sphere_t;

static uint32_t midpoint(sphere_t *s, uint32_t *cache, size_t nv0, uint32_t a, uint32_t b) {
  uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
  uint32_t *slot = &cache[(size_t)lo * nv0 + hi];
  if (*slot) return *slot;
  float *p = s->pos + 3 * s->nverts;
  double len = 0;
  for (int k = 0; k < 3; k++) {
    p[k] = 0.5f * (s->pos[3 * a + k] + s->pos[3 * b + k]);
    len += (double)p[k] * p[k];
  }
  for (int k = 0; k < 3; k++) p[k] = (float)(p[k] / sqrt(len));
  return *slot = (uint32_t)s->nverts++;
}

/* Unit icosphere, counter-clockwise seen from outside. */
static void make_icosphere(sphere_t *s, int levels) {
  const double t = (1.0 + sqrt(5.0)) / 2.0;
  const double v[12][3] = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                           {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  const uint32_t f[20][3] = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                             {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                             {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  s->nverts = 12;
  s->ntris = 20;
  for (int i = 0; i < 12; i++) {
    double n = sqrt(v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2]);
    for (int k = 0; k < 3; k++) s->pos[3 * i + k] = (float)(v[i][k] / n);
  }
  memcpy(s->tris, f, sizeof f);
  for (int l = 0; l < levels; l++) {
    size_t nv0 = s->nverts, nt0 = s->ntris;
    uint32_t *cache = calloc(nv0 * nv0, sizeof *cache);
    static uint32_t out[3 * 5120];
    for (size_t i = 0; i < nt0; i++) {
      uint32_t a = s->tris[3 * i], b = s->tris[3 * i + 1], c = s->tris[3 * i + 2];
      uint32_t ab = midpoint(s, cache, nv0, a, b), bc = midpoint(s, cache, nv0, b, c),
               ca = midpoint(s, cache, nv0, c, a);
      const uint32_t q[4][3] = {{a, ab, ca}, {b, bc, ab}, {c, ca, bc}, {ab, bc, ca}};
      memcpy(out + 12 * i, q, sizeof q);
    }
    s->ntris = 4 * nt0;
    memcpy(s->tris, out, s->ntris * 3 * sizeof *out);
    free(cache);
  }
}

static const uint8_t *px(const uint8_t *img, int x, int y_down) {
  /* Renderer images are bottom-up; tests speak window coordinates (y down). */
  return img + ((size_t)(H - 1 - y_down) * W + x) * 3;
}

static int same_px(const uint8_t *a, const uint8_t *b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }
static int luma(const uint8_t *p) { return (2 * p[0] + 5 * p[1] + p[2]) / 8; }

static const float CENTRE[3] = {0.10f, -0.05f, 0.20f};
static const float RADIUS = 0.05f;

int main(void) {
  static sphere_t unit, s;
  make_icosphere(&unit, 3);
  s = unit;
  for (size_t i = 0; i < s.nverts; i++)
    for (int k = 0; k < 3; k++) s.pos[3 * i + k] = CENTRE[k] + RADIUS * unit.pos[3 * i + k];
  const float colour[3] = {0.6f, 0.15f, 0.12f};

  verr_t err = {{0}};
  render_t *r = NULL;
  if (render_open(&r, W, H, 2, &err) != 0) {
    fprintf(stderr, "%s\n", err.msg);
    CHECK(!"render_open");
    return check_report("test_render");
  }
  double bmin[3], bmax[3];
  for (int k = 0; k < 3; k++) bmin[k] = CENTRE[k] - RADIUS, bmax[k] = CENTRE[k] + RADIUS;
  camera_t cam;
  CHECK(camera_frame(&cam, bmin, bmax, W, H) == 0);

  static uint8_t bg[W * H * 3], img[W * H * 3], dented[W * H * 3];
  render_begin(r, &cam);
  memcpy(bg, render_end(r), sizeof bg);
  render_begin(r, &cam);
  CHECK(render_mesh(r, s.pos, s.nverts, s.tris, s.ntris, colour, &err) == 0);
  memcpy(img, render_end(r), sizeof img);

  /* Centre drawn, corners untouched. */
  double c3[3] = {CENTRE[0], CENTRE[1], CENTRE[2]}, cx, cy;
  CHECK(camera_project(&cam, c3, &cx, &cy) == 1);
  CHECK_NEAR(cx, W / 2.0, 1.0);
  CHECK_NEAR(cy, H / 2.0, 1.0);
  int icx = (int)cx, icy = (int)cy;
  CHECK(!same_px(px(img, icx, icy), px(bg, icx, icy)));
  CHECK(px(img, icx, icy)[0] > px(img, icx, icy)[2] + 30); /* the sphere's red, not the grey background */
  CHECK(same_px(px(img, 0, 0), px(bg, 0, 0)));
  CHECK(same_px(px(img, W - 1, H - 1), px(bg, W - 1, H - 1)));
  CHECK(same_px(px(img, 0, H - 1), px(bg, 0, H - 1)));
  /* The background is a gradient, lighter at the top. */
  CHECK(luma(px(bg, 0, 0)) > luma(px(bg, 0, H - 1)));

  /* Screen radius: farthest projected vertex from the projected centre. */
  double R = 0;
  for (size_t i = 0; i < s.nverts; i++) {
    double p[3] = {s.pos[3 * i], s.pos[3 * i + 1], s.pos[3 * i + 2]}, x, y;
    camera_project(&cam, p, &x, &y);
    double d = hypot(x - cx, y - cy);
    if (d > R) R = d;
  }
  CHECK(R > 0.25 * H && R < 0.5 * H); /* framed: large but whole */
  for (size_t i = 0; i < s.nverts; i++) {
    double p[3] = {s.pos[3 * i], s.pos[3 * i + 1], s.pos[3 * i + 2]}, x, y;
    camera_project(&cam, p, &x, &y);
    CHECK(x >= 0 && x < W && y >= 0 && y < H);
  }

  /* Shading: towards the key light (up-left on screen) is brighter than the
   * opposite side, and the far side still shows some light (fill, ambient). */
  double lx = RENDER_KEY_LIGHT_X, ly = -RENDER_KEY_LIGHT_Y, ln = hypot(lx, ly);
  int litx = (int)(cx + 0.6 * R * lx / ln), lity = (int)(cy + 0.6 * R * ly / ln);
  int farx = (int)(cx - 0.6 * R * lx / ln), fary = (int)(cy - 0.6 * R * ly / ln);
  int lit = luma(px(img, litx, lity)), dark = luma(px(img, farx, fary));
  printf("luma lit %d, far %d, centre %d\n", lit, dark, luma(px(img, icx, icy)));
  CHECK(lit > dark + 40);
  CHECK(!same_px(px(img, farx, fary), px(bg, farx, fary)));

  /* PNG round trip: same size, same pixels, rows flipped to top-down. */
  char path[64];
  snprintf(path, sizeof path, "/tmp/test_render_%ld.png", (long)getpid());
  CHECK(png_write_rgb(path, W, H, img, 1, &err) == 0);
  png_image in;
  memset(&in, 0, sizeof in);
  in.version = PNG_IMAGE_VERSION;
  static uint8_t back[W * H * 3];
  CHECK(png_image_begin_read_from_file(&in, path) != 0);
  CHECK(in.width == W && in.height == H);
  in.format = PNG_FORMAT_RGB;
  if (in.width == W && in.height == H) {
    CHECK(png_image_finish_read(&in, NULL, back, W * 3, NULL) != 0);
    int diff = 0;
    for (int y = 0; y < H; y++) diff += memcmp(back + (size_t)y * W * 3, px(img, 0, y), (size_t)W * 3) != 0;
    CHECK(diff == 0);
  } else {
    png_image_free(&in);
  }
  remove(path);
  CHECK(png_write_rgb("/nonexistent-dir/x.png", W, H, img, 1, &err) == -1);
  CHECK(strstr(err.msg, "/nonexistent-dir/x.png") != NULL);

  /* Dent: push the vertex that faces the camera most (but is off-centre so
   * near and far regions are distinct) outward by a third of the radius. */
  size_t best = 0;
  double best_score = -1;
  for (size_t i = 0; i < s.nverts; i++) {
    double to_eye[3], n = 0, d = 0;
    for (int k = 0; k < 3; k++) to_eye[k] = cam.eye[k] - s.pos[3 * i + k], n += to_eye[k] * to_eye[k];
    for (int k = 0; k < 3; k++) d += unit.pos[3 * i + k] * to_eye[k] / sqrt(n);
    double p[3] = {s.pos[3 * i], s.pos[3 * i + 1], s.pos[3 * i + 2]}, x, y;
    camera_project(&cam, p, &x, &y);
    double off = hypot(x - cx, y - cy) / R;
    if (off > 0.3 && off < 0.5 && d > best_score) best_score = d, best = i;
  }
  CHECK(best_score > 0.8);
  double v0[3] = {s.pos[3 * best], s.pos[3 * best + 1], s.pos[3 * best + 2]}, vx, vy;
  camera_project(&cam, v0, &vx, &vy);
  for (int k = 0; k < 3; k++) s.pos[3 * best + k] += RADIUS / 3.0f * unit.pos[3 * best + k];
  render_begin(r, &cam);
  CHECK(render_mesh(r, s.pos, s.nverts, s.tris, s.ntris, colour, &err) == 0);
  memcpy(dented, render_end(r), sizeof dented);
  int near_changed = 0, far_changed = 0, near_total = 0;
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      double d = hypot(x + 0.5 - vx, y + 0.5 - vy);
      int changed = !same_px(px(img, x, y), px(dented, x, y));
      if (d < 0.15 * R) near_total++, near_changed += changed;
      if (d > 0.7 * R) far_changed += changed;
    }
  printf("dent: %d of %d pixels near the vertex changed, %d far away\n", near_changed, near_total, far_changed);
  CHECK(near_changed > near_total / 2);
  CHECK(far_changed == 0);

  /* Tool: grey when idle, yellow in contact; drawn where it projects. */
  const float tip[3] = {CENTRE[0] + 1.6f * RADIUS, CENTRE[1], CENTRE[2]};
  double t3[3] = {tip[0], tip[1], tip[2]}, tx, ty;
  camera_project(&cam, t3, &tx, &ty);
  static uint8_t tool[W * H * 3];
  for (int contact = 0; contact < 2; contact++) {
    render_begin(r, &cam);
    render_tool(r, tip, 0.15f * RADIUS, 2 * RADIUS, contact);
    memcpy(tool, render_end(r), sizeof tool);
    const uint8_t *p = px(tool, (int)tx, (int)ty);
    CHECK(!same_px(p, px(bg, (int)tx, (int)ty)));
    if (contact)
      CHECK(p[0] > p[2] + 80 && p[1] > p[2] + 60);
    else
      CHECK(abs(p[0] - p[2]) < 30);
    /* The shaft goes up: a pixel above the tip (y smaller) is drawn too. */
    CHECK(!same_px(px(tool, (int)tx, (int)ty - 12), px(bg, (int)tx, (int)ty - 12)));
    /* And nothing below the tip sphere. */
    CHECK(same_px(px(tool, (int)tx, (int)ty + 12), px(bg, (int)tx, (int)ty + 12)));
  }

  /* Force bar with palpation thresholds (ST 0.6, MPF 0.9, SFT 1.5 of 4 N):
   * green below ST, orange above ST, red above MPF; a line at each level
   * left of the bar, beyond the 1 N ticks. Bar: x from W-28 to W-16, from
   * 16 px above the bottom, 0.4 H tall. */
  static uint8_t bar[W * H * 3];
  const double forces[3] = {0.5, 0.7, 1.2};
  int bx = W - 22, by = H - 1 - 18;
  for (int i = 0; i < 3; i++) {
    render_begin(r, &cam);
    render_force_bar_levels(r, forces[i], 4.0, 0.6, 0.9, 1.5);
    memcpy(bar, render_end(r), sizeof bar);
    const uint8_t *p = px(bar, bx, by);
    printf("force bar at %.1f N: rgb %d %d %d\n", forces[i], p[0], p[1], p[2]);
    if (i == 0) CHECK(p[1] > p[0] && p[1] > p[2]);                          /* green */
    if (i == 1) CHECK(p[0] > 200 && p[1] > 110 && p[1] < 205 && p[2] < 80); /* orange */
    if (i == 2) CHECK(p[0] > 200 && p[1] < 100 && p[2] < 80);               /* red */
    const double lv[3] = {0.6, 0.9, 1.5};
    for (int k = 0; k < 3; k++) {
      int yl = H - 1 - (int)(16 + lv[k] / 4.0 * 0.4 * H), found = 0;
      for (int dy = -1; dy <= 1; dy++) found |= !same_px(px(bar, W - 35, yl + dy), px(bg, W - 35, yl + dy));
      CHECK(found);
    }
    /* Between the levels, left of the ticks: background. */
    int ymid = H - 1 - (int)(16 + 1.2 / 4.0 * 0.4 * H);
    CHECK(same_px(px(bar, W - 35, ymid), px(bg, W - 35, ymid)));
  }

  /* A stone (render_object) inside the organ shows through as a ghost in
   * its colour; outside it is drawn solid. */
  static uint8_t organ_only[W * H * 3], with_stone[W * H * 3];
  const float stone_rgb[3] = {0.9f, 0.85f, 0.2f};
  render_begin(r, &cam);
  CHECK(render_mesh(r, s.pos, s.nverts, s.tris, s.ntris, colour, &err) == 0);
  memcpy(organ_only, render_end(r), sizeof organ_only);
  render_begin(r, &cam);
  CHECK(render_mesh(r, s.pos, s.nverts, s.tris, s.ntris, colour, &err) == 0);
  render_object(r, CENTRE, 0.3f * RADIUS, stone_rgb);
  memcpy(with_stone, render_end(r), sizeof with_stone);
  const uint8_t *ghost = px(with_stone, (int)cx, (int)cy), *org = px(organ_only, (int)cx, (int)cy);
  printf("stone inside: rgb %d %d %d over organ %d %d %d\n", ghost[0], ghost[1], ghost[2], org[0], org[1], org[2]);
  CHECK(ghost[1] > org[1] + 20); /* tinted towards the stone's yellow */
  render_begin(r, &cam);
  render_object(r, tip, 0.3f * RADIUS, stone_rgb);
  memcpy(with_stone, render_end(r), sizeof with_stone);
  const uint8_t *out = px(with_stone, (int)tx, (int)ty);
  CHECK(out[0] > out[2] + 60 && out[1] > out[2] + 60); /* solid yellow */

  /* Bad arguments fail with a message instead of crashing. */
  render_t *bad = NULL;
  CHECK(render_open(&bad, 0, 10, 1, &err) == -1 && bad == NULL);
  CHECK(camera_frame(&cam, bmin, (double[3]){NAN, 0, 0}, W, H) == -1);
  double nan3[3] = {NAN, 0, 0};
  CHECK(camera_project(&cam, nan3, &vx, &vy) == 0 && vx == -1 && vy == -1);

  render_close(r);
  return check_report("test_render");
}
