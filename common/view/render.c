/* SPDX-License-Identifier: Apache-2.0 */
#include "view/render.h"

#include <GL/gl.h>
#include <GL/osmesa.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mesh.h"

#if defined(__SANITIZE_ADDRESS__)
/* Mesa 22's OSMesa leaks ~480 bytes per process inside the library (its
 * buffer list outlives OSMesaDestroyContext; a bare create/bind/destroy
 * program shows the same). LeakSanitizer asks this hook for suppressions, so
 * every program linking the renderer stays clean in sanitizer builds; only
 * allocations made from within libOSMesa are matched. */
const char *__lsan_default_suppressions(void);
/* The window viewer (window.c) adds SDL2, which opens libdbus (IME and
 * screensaver) and, as a library must, never calls dbus_shutdown: libdbus's
 * own allocations stay. */
const char *__lsan_default_suppressions(void) { return "leak:libOSMesa.so\nleak:libdbus-1.so\n"; }
/* Without this every exit prints the suppression table; LSAN_OPTIONS still
 * overrides it. */
const char *__lsan_default_options(void);
const char *__lsan_default_options(void) { return "print_suppressions=0"; }
#endif

/* Tessellation of the tool primitives: smooth enough at a few tens of pixels. */
#define SLICES 24
#define STACKS 16
#define PRIM_MAX_VERTS ((STACKS + 1) * (SLICES + 1))
#define PRIM_MAX_TRIS (2 * STACKS * SLICES)

/* A small lit primitive in unit size, scaled into place when drawn. */
typedef struct prim {
  size_t nverts, ntris;
  float pos[3 * PRIM_MAX_VERTS];
  float nrm[3 * PRIM_MAX_VERTS];
  uint32_t tris[3 * PRIM_MAX_TRIS];
} prim_t;

struct render {
  OSMesaContext ctx;
  int w, h;       /* output size */
  int ss;         /* supersampling factor */
  int bw, bh;     /* GL buffer size = output * ss */
  uint16_t *buf;  /* bw * bh * 4, linear RGBA, rows bottom-up */
  uint8_t *out;   /* w * h * 3, sRGB */
  float *normals; /* scratch for render_mesh */
  size_t normals_cap;
  prim_t sphere, cylinder;
  uint8_t srgb[65536]; /* linear 16-bit -> sRGB 8-bit */
};

/* Linear colours (they are encoded to sRGB at the end). */
static const float BG_TOP[3] = {0.045f, 0.050f, 0.060f};
static const float BG_BOTTOM[3] = {0.006f, 0.0065f, 0.008f};
static const float TOOL_IDLE[3] = {0.30f, 0.31f, 0.33f};
static const float TOOL_CONTACT[3] = {1.0f, 0.75f, 0.05f};
static const float PROXY[3] = {0.05f, 0.70f, 0.10f};
/* Opacity of tool and proxy parts hidden behind tissue. */
#define GHOST_ALPHA 0.35f
/* Emission of tools and proxy as a fraction of their colour. */
#define GLOW 0.30f

static void prim_add_vertex(prim_t *p, float x, float y, float z, float nx, float ny, float nz) {
  float *v = p->pos + 3 * p->nverts, *n = p->nrm + 3 * p->nverts;
  v[0] = x, v[1] = y, v[2] = z;
  n[0] = nx, n[1] = ny, n[2] = nz;
  p->nverts++;
}

static void prim_add_tri(prim_t *p, size_t a, size_t b, size_t c) {
  uint32_t *t = p->tris + 3 * p->ntris++;
  t[0] = (uint32_t)a, t[1] = (uint32_t)b, t[2] = (uint32_t)c;
}

/* Unit sphere at the origin, latitude-longitude, counter-clockwise outside. */
static void make_sphere(prim_t *p) {
  p->nverts = p->ntris = 0;
  for (int i = 0; i <= STACKS; i++) {
    double th = M_PI * i / STACKS; /* from +z down */
    for (int j = 0; j <= SLICES; j++) {
      double ph = 2.0 * M_PI * j / SLICES;
      float x = (float)(sin(th) * cos(ph)), y = (float)(sin(th) * sin(ph)), z = (float)cos(th);
      prim_add_vertex(p, x, y, z, x, y, z);
    }
  }
  for (int i = 0; i < STACKS; i++)
    for (int j = 0; j < SLICES; j++) {
      size_t a = (size_t)i * (SLICES + 1) + j, b = a + SLICES + 1;
      prim_add_tri(p, a, b, a + 1);
      prim_add_tri(p, a + 1, b, b + 1);
    }
}

/* Unit-radius cylinder from z = 0 to z = 1 with a cap on top. */
static void make_cylinder(prim_t *p) {
  p->nverts = p->ntris = 0;
  for (int j = 0; j <= SLICES; j++) {
    double ph = 2.0 * M_PI * j / SLICES;
    float x = (float)cos(ph), y = (float)sin(ph);
    prim_add_vertex(p, x, y, 0, x, y, 0);
    prim_add_vertex(p, x, y, 1, x, y, 0);
  }
  for (int j = 0; j < SLICES; j++) {
    size_t a = 2 * (size_t)j;
    prim_add_tri(p, a, a + 2, a + 1);
    prim_add_tri(p, a + 1, a + 2, a + 3);
  }
  size_t centre = p->nverts;
  prim_add_vertex(p, 0, 0, 1, 0, 0, 1);
  for (int j = 0; j <= SLICES; j++) {
    double ph = 2.0 * M_PI * j / SLICES;
    prim_add_vertex(p, (float)cos(ph), (float)sin(ph), 1, 0, 0, 1);
  }
  for (int j = 0; j < SLICES; j++) prim_add_tri(p, centre, centre + 1 + j, centre + 2 + j);
}

static void fill_srgb_table(uint8_t *lut) {
  for (int i = 0; i < 65536; i++) {
    double l = i / 65535.0;
    double s = l <= 0.0031308 ? 12.92 * l : 1.055 * pow(l, 1.0 / 2.4) - 0.055;
    lut[i] = (uint8_t)lrint(s * 255.0);
  }
}

/* Fixed GL state for the whole life of the context. */
static void setup_gl_state(void) {
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glShadeModel(GL_SMOOTH);
  /* Tool primitives are scaled, possibly non-uniformly: renormalise. */
  glEnable(GL_NORMALIZE);
  /* Cut or open surfaces show their inside: light both faces, cull none. */
  glLightModeli(GL_LIGHT_MODEL_TWO_SIDE, GL_TRUE);
  glLightModeli(GL_LIGHT_MODEL_LOCAL_VIEWER, GL_TRUE);
  const GLfloat ambient[4] = {0.05f, 0.05f, 0.055f, 1};
  glLightModelfv(GL_LIGHT_MODEL_AMBIENT, ambient);

  const GLfloat key_diffuse[4] = {0.90f, 0.88f, 0.85f, 1}, key_specular[4] = {0.7f, 0.7f, 0.7f, 1};
  const GLfloat fill_diffuse[4] = {0.22f, 0.25f, 0.30f, 1}, none[4] = {0, 0, 0, 1};
  glLightfv(GL_LIGHT0, GL_DIFFUSE, key_diffuse);
  glLightfv(GL_LIGHT0, GL_SPECULAR, key_specular);
  glLightfv(GL_LIGHT0, GL_AMBIENT, none);
  glLightfv(GL_LIGHT1, GL_DIFFUSE, fill_diffuse);
  glLightfv(GL_LIGHT1, GL_SPECULAR, none);
  glLightfv(GL_LIGHT1, GL_AMBIENT, none);
  glEnable(GL_LIGHT0);
  glEnable(GL_LIGHT1);

  glColorMaterial(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE);
  glEnable(GL_COLOR_MATERIAL);
  glEnableClientState(GL_VERTEX_ARRAY);
  glEnableClientState(GL_NORMAL_ARRAY);
}

int render_open(render_t **out, int width, int height, int supersample, verr_t *err) {
  *out = NULL;
  if (width < 1 || height < 1 || width > RENDER_MAX_SIZE || height > RENDER_MAX_SIZE)
    return verr_set(err, "render: size %dx%d out of range (1..%d)", width, height, RENDER_MAX_SIZE);
  if (supersample < 1 || supersample > 4)
    return verr_set(err, "render: supersample %d out of range (1..4)", supersample);
  render_t *r = calloc(1, sizeof *r);
  if (!r) return verr_set(err, "render: out of memory");
  r->w = width, r->h = height, r->ss = supersample;
  r->bw = width * supersample, r->bh = height * supersample;
  r->buf = calloc((size_t)r->bw * r->bh * 4, sizeof *r->buf);
  r->out = calloc((size_t)width * height * 3, 1);
  if (!r->buf || !r->out) {
    render_close(r);
    return verr_set(err, "render: out of memory for a %dx%d frame", width, height);
  }
  r->ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, NULL);
  if (!r->ctx) {
    render_close(r);
    return verr_set(err, "OSMesa: cannot create an RGBA context with a 24-bit depth buffer");
  }
  /* 16 bits per channel: see the header on banding. */
  if (!OSMesaMakeCurrent(r->ctx, r->buf, GL_UNSIGNED_SHORT, r->bw, r->bh)) {
    render_close(r);
    return verr_set(err, "OSMesa: cannot bind a %dx%d 16-bit RGBA buffer", width * supersample, height * supersample);
  }
  setup_gl_state();
  GLenum e = glGetError();
  if (e != GL_NO_ERROR) {
    render_close(r);
    return verr_set(err, "OpenGL: setup failed with error 0x%04x", (unsigned)e);
  }
  make_sphere(&r->sphere);
  make_cylinder(&r->cylinder);
  fill_srgb_table(r->srgb);
  *out = r;
  return 0;
}

void render_close(render_t *r) {
  if (!r) return;
  if (r->ctx) OSMesaDestroyContext(r->ctx);
  free(r->buf);
  free(r->out);
  free(r->normals);
  free(r);
}

static void draw_background(void) {
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glDisable(GL_LIGHTING);
  glDisable(GL_DEPTH_TEST);
  glBegin(GL_QUADS);
  glColor3fv(BG_BOTTOM);
  glVertex2f(-1, -1);
  glVertex2f(1, -1);
  glColor3fv(BG_TOP);
  glVertex2f(1, 1);
  glVertex2f(-1, 1);
  glEnd();
  glEnable(GL_DEPTH_TEST);
}

void render_begin(render_t *r, const camera_t *cam) {
  OSMesaMakeCurrent(r->ctx, r->buf, GL_UNSIGNED_SHORT, r->bw, r->bh);
  glViewport(0, 0, r->bw, r->bh);
  glClearColor(0, 0, 0, 1);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  draw_background();

  /* Light positions are transformed by the modelview current when they are
   * set: with the identity they stay fixed to the camera. */
  glLoadIdentity();
  const GLfloat key_dir[4] = {RENDER_KEY_LIGHT_X, RENDER_KEY_LIGHT_Y, RENDER_KEY_LIGHT_Z, 0};
  const GLfloat fill_dir[4] = {0.65f, -0.25f, 0.45f, 0};
  glLightfv(GL_LIGHT0, GL_POSITION, key_dir);
  glLightfv(GL_LIGHT1, GL_POSITION, fill_dir);

  glMatrixMode(GL_PROJECTION);
  glLoadMatrixf(cam->proj);
  glMatrixMode(GL_MODELVIEW);
  glLoadMatrixf(cam->view);
  glEnable(GL_LIGHTING);
}

static void set_material(float specular, float shininess) {
  const GLfloat s[4] = {specular, specular, specular, 1};
  glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, s);
  glMaterialf(GL_FRONT_AND_BACK, GL_SHININESS, shininess);
}

int render_mesh(render_t *r, const float *pos, size_t nverts, const uint32_t *tris, size_t ntris, const float rgb[3],
                verr_t *err) {
  if (nverts == 0 || ntris == 0) return 0;
  if (ntris > (size_t)INT_MAX / 3) return verr_set(err, "render: %zu triangles exceed the GL's index count", ntris);
  if (nverts > r->normals_cap) {
    float *n = realloc(r->normals, nverts * 3 * sizeof *n);
    if (!n) return verr_set(err, "render: out of memory for %zu normals", nverts);
    r->normals = n;
    r->normals_cap = nverts;
  }
  mesh_vertex_normals_f(nverts, pos, ntris, tris, r->normals);
  /* Moist tissue: a soft, fairly broad highlight. */
  set_material(0.35f, 40.0f);
  glColor3fv(rgb);
  glVertexPointer(3, GL_FLOAT, 0, pos);
  glNormalPointer(GL_FLOAT, 0, r->normals);
  glDrawElements(GL_TRIANGLES, (GLsizei)(3 * ntris), GL_UNSIGNED_INT, tris);
  return 0;
}

static void draw_prim(const prim_t *p, const float at[3], float sx, float sy, float sz) {
  glPushMatrix();
  glTranslatef(at[0], at[1], at[2]);
  glScalef(sx, sy, sz);
  glVertexPointer(3, GL_FLOAT, 0, p->pos);
  glNormalPointer(GL_FLOAT, 0, p->nrm);
  glDrawElements(GL_TRIANGLES, (GLsizei)(3 * p->ntris), GL_UNSIGNED_INT, p->tris);
  glPopMatrix();
}

/* A probe shape: tip sphere plus a thin shaft up +z (length 0: sphere only). */
static void draw_probe(render_t *r, const float tip[3], float tip_radius, float length) {
  draw_prim(&r->sphere, tip, tip_radius, tip_radius, tip_radius);
  float shaft = 0.45f * tip_radius;
  if (length > 0) draw_prim(&r->cylinder, tip, shaft, shaft, length);
}

/* Draws the probe shape opaque, then its hidden parts again as a faint
 * ghost: while pressing, the device tip is inside the tissue and the proxy
 * half in it, and a trainee needs to see both. The ghost pass draws only
 * where something is in front and writes no depth. */
static void draw_ghosted(render_t *r, const float *rgb, const float at[3], float radius, float length) {
  /* Some self-illumination: a vertical shaft is only grazed by the key light
   * from above and would read olive instead of the state colour. */
  const GLfloat glow[4] = {GLOW * rgb[0], GLOW * rgb[1], GLOW * rgb[2], 1}, none[4] = {0, 0, 0, 1};
  glMaterialfv(GL_FRONT_AND_BACK, GL_EMISSION, glow);
  glColor3fv(rgb);
  draw_probe(r, at, radius, length);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_FALSE);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glColor4f(rgb[0], rgb[1], rgb[2], GHOST_ALPHA);
  draw_probe(r, at, radius, length);
  glMaterialfv(GL_FRONT_AND_BACK, GL_EMISSION, none);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LEQUAL);
}

void render_tool(render_t *r, const float tip[3], float tip_radius, float length, int in_contact) {
  /* Metal: a tight, bright highlight. */
  set_material(0.8f, 80.0f);
  draw_ghosted(r, in_contact ? TOOL_CONTACT : TOOL_IDLE, tip, tip_radius, length);
}

void render_proxy(render_t *r, const float p[3], float radius) {
  set_material(0.3f, 30.0f);
  draw_ghosted(r, PROXY, p, radius, 0);
}

void render_object(render_t *r, const float centre[3], float radius, const float rgb[3]) {
  /* Stone: hard and dry, a modest highlight. */
  set_material(0.4f, 50.0f);
  draw_ghosted(r, rgb, centre, radius, 0);
}

void render_force_bar(render_t *r, double force, double max_force) {
  render_force_bar_levels(r, force, max_force, 0, 0, 0);
}

void render_force_bar_levels(render_t *r, double force, double max_force, double st, double mpf, double sft) {
  if (!(max_force > 0) || !isfinite(max_force)) max_force = 1.0;
  double frac = isfinite(force) && force > 0 ? force / max_force : 0.0;
  if (frac > 1.0) frac = 1.0;

  /* Overlay in output pixels (origin bottom-left); the projection scales it
   * to the supersampled buffer. */
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glOrtho(0, r->w, 0, r->h, -1, 1);
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glDisable(GL_LIGHTING);
  glDisable(GL_DEPTH_TEST);

  float bw = 12.0f, bh = 0.4f * (float)r->h;
  float x0 = (float)r->w - 16.0f - bw, y0 = 16.0f, x1 = x0 + bw, y1 = y0 + bh;
  float fill = y0 + (float)frac * bh;
  double f = isfinite(force) ? force : 0.0;
  int levels = (isfinite(st) && st > 0) || (isfinite(mpf) && mpf > 0);
  if (levels ? (mpf > 0 && f > mpf) : frac > 0.8)
    glColor3f(0.85f, 0.05f, 0.03f); /* red */
  else if (levels ? (st > 0 && f > st) : frac > 0.5)
    glColor3f(0.95f, levels ? 0.45f : 0.70f, 0.02f); /* orange (levels) or yellow */
  else
    glColor3f(0.10f, 0.60f, 0.12f);
  glBegin(GL_QUADS);
  glVertex2f(x0, y0);
  glVertex2f(x1, y0);
  glVertex2f(x1, fill);
  glVertex2f(x0, fill);
  glEnd();

  glLineWidth((float)r->ss);
  glColor3f(0.45f, 0.45f, 0.45f);
  glBegin(GL_LINE_LOOP);
  glVertex2f(x0, y0);
  glVertex2f(x1, y0);
  glVertex2f(x1, y1);
  glVertex2f(x0, y1);
  glEnd();
  /* One tick per newton, left of the bar, when ticks are at least 4 px apart. */
  if (bh / max_force >= 4.0) {
    glBegin(GL_LINES);
    for (int n = 1; n < max_force; n++) {
      float y = y0 + (float)(n / max_force) * bh;
      glVertex2f(x0 - 5.0f, y);
      glVertex2f(x0, y);
    }
    glEnd();
  }
  /* Threshold lines across the bar (and a little beyond on the left):
   * ST orange, MPF red, SFT dark red. */
  const double lv[3] = {st, mpf, sft};
  static const float lc[3][3] = {{0.95f, 0.45f, 0.02f}, {0.85f, 0.05f, 0.03f}, {0.45f, 0.0f, 0.0f}};
  glBegin(GL_LINES);
  for (int k = 0; k < 3; k++) {
    if (!(isfinite(lv[k]) && lv[k] > 0 && lv[k] <= max_force)) continue;
    float y = y0 + (float)(lv[k] / max_force) * bh;
    glColor3f(lc[k][0], lc[k][1], lc[k][2]);
    glVertex2f(x0 - 8.0f, y);
    glVertex2f(x1, y);
  }
  glEnd();
  glEnable(GL_DEPTH_TEST);
  glEnable(GL_LIGHTING);
}

const uint8_t *render_end(render_t *r) {
  glFinish();
  /* Box filter in linear light, then encode: averaging sRGB values would
   * darken edges. */
  const int ss = r->ss, n = ss * ss;
  for (int y = 0; y < r->h; y++)
    for (int x = 0; x < r->w; x++) {
      uint32_t sum[3] = {0, 0, 0};
      for (int sy = 0; sy < ss; sy++) {
        const uint16_t *row = r->buf + ((size_t)(y * ss + sy) * r->bw + (size_t)x * ss) * 4;
        for (int sx = 0; sx < ss; sx++)
          for (int k = 0; k < 3; k++) sum[k] += row[4 * sx + k];
      }
      uint8_t *o = r->out + ((size_t)y * r->w + x) * 3;
      for (int k = 0; k < 3; k++) o[k] = r->srgb[(sum[k] + n / 2) / n];
    }
  return r->out;
}
