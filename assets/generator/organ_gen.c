/* viscera-organ-gen OUTDIR: writes the built-in organ meshes (the source of truth
 * for the .obj files in assets/meshes) and prints a table of them.
 *
 * Units metres, z up; every mesh is centred in x and y with its lowest point at
 * z = 0. The closed organs are swept surfaces: a pole, R rings of S vertices, a
 * pole (V = 2 + R*S, T = 2*R*S, a sphere's topology), each ring a star-shaped
 * curve in a plane x = const with x strictly monotone from ring to ring: slices
 * never meet, so the smooth surface cannot pass through itself, and the rings
 * are fine enough for the triangles to follow it. Shapes are smooth closed-form
 * functions, then scaled per axis to the target box: no randomness, the output
 * is the same on every run. gallbladder has 5,392 vertices / 10,780 triangles
 * (R*S = 5,390; the documents' 10,782 would need R*S = 5,391 = 9 * 599).
 *
 * tissue_block is the exception: an open, flat patch (45 vertices / 66 triangles
 * in 7 staggered rows of 6 and 7 vertices, 10 x 6 cm at z = 0, normals +z, so
 * its short sides zigzag). That is the simple tissue of the source documents; a
 * closed slab cannot have those counts (a closed sphere-like mesh has T = 2V - 4). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "mesh.h"
#include "mesh_check.h"
#include "vmath.h"

#define PI 3.14159265358979323846

typedef void (*surface_fn)(double theta, double phi, double p[3]);

typedef struct organ {
  const char *name;  /* file stem */
  const char *about; /* first line of the OBJ */
  double size[3];    /* target bounding box, metres */
  int rings, segs;   /* closed sweep resolution; 0 for the tissue patch */
  surface_fn surf;
} organ_t;

static double smoothstep(double a, double b, double x) {
  double t = (x - a) / (b - a);
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  return t * t * (3 - 2 * t);
}

/* Angular distance in [0, pi]. */
static double angle_dist(double a, double b) { return fabs(remainder(a - b, 2 * PI)); }

/* Each shape maps theta in [0, pi] (pole to pole along x) and phi (around) to a
 * point in units of the half length; the final size comes from scaling. */

/* Elongated, curved (concave on +y, the visceral side, with a shallow dent
 * there), larger at the upper pole. */
static void spleen_point(double th, double ph, double p[3]) {
  double x = -cos(th), s = sin(th);
  double env = pow(s, 0.75) * (1 + 0.18 * x);
  double dent = 1 - 0.3 * pow(fmax(0, cos(ph)), 3);
  p[0] = x;
  p[1] = 0.45 * env * cos(ph) * dent + 0.35 * x * x;
  p[2] = 0.28 * env * sin(ph) * dent;
}

/* Bean: bent toward -y, the medial side, where the hilum is a deep dent at
 * mid-length. */
static void kidney_point(double th, double ph, double p[3]) {
  double x = -cos(th), s = sin(th);
  double env = pow(s, 0.85);
  double d = angle_dist(ph, PI);
  double hilum = 1 - 0.5 * exp(-(x / 0.3) * (x / 0.3)) * exp(-(d / 0.75) * (d / 0.75));
  p[0] = x;
  p[1] = 0.55 * env * cos(ph) * hilum - 0.18 * x * x;
  p[2] = 0.32 * env * sin(ph) * hilum;
}

/* Pear: round fundus at +x, tapering to a narrow neck at -x that bends away. */
static void gallbladder_point(double th, double ph, double p[3]) {
  double x = -cos(th), s = sin(th), u = (1 + x) / 2;
  double r = 0.39 * pow(s, 0.6) * (0.28 + 0.72 * smoothstep(0, 0.75, u));
  double neck = (1 - u) * (1 - u) * (1 - u);
  p[0] = x;
  p[1] = r * cos(ph) + 0.12 * neck;
  p[2] = r * sin(ph) + 0.08 * neck;
}

/* Wedge: thick domed right lobe at -x, thinning to the left lobe tip, flat
 * underside rising toward the left, left lobe curling forward (-y). */
static void liver_point(double th, double ph, double p[3]) {
  double x = -cos(th), s = sin(th), u = (1 + x) / 2;
  double env = pow(s, 0.6);
  double a = 0.75 * (1 - 0.5 * u) * env, b = 0.5 * (1 - 0.75 * u) * env;
  double sz = sin(ph);
  p[0] = x;
  p[1] = a * cos(ph) - 0.25 * u * u;
  p[2] = b * sz * (sz < 0 ? 0.45 : 1) + 0.12 * u * u;
}

static const organ_t ORGANS[] = {
    {"tissue_block", "simple tissue patch, open, 10 x 6 cm", {0.10, 0.06, 0}, 0, 0, NULL},
    {"spleen", "spleen, closed, 12 x 7 x 4 cm", {0.12, 0.07, 0.04}, 23, 26, spleen_point},
    {"kidney", "kidney, closed, 11 x 6 x 3.5 cm", {0.11, 0.06, 0.035}, 37, 54, kidney_point},
    {"gallbladder", "gallbladder, closed, 9 x 3.5 x 3.5 cm", {0.09, 0.035, 0.035}, 77, 70, gallbladder_point},
    /* 23,522 vertices: the mesh size of the nearest-feature query benchmark. */
    {"liver_large", "liver, closed, 20 x 14 x 10 cm", {0.20, 0.14, 0.10}, 140, 168, liver_point},
};

/* Rows alternate 6 (even rows, offset by half a step) and 7 vertices; each pair
 * of rows is a zigzag strip of 6 + 5 triangles, counter-clockwise from above. */
static int build_tissue(mesh_t *m, verr_t *err) {
  enum { ROWS = 7, LONG = 7, SHORT = 6 };
  if (mesh_alloc(m, 4 * SHORT + 3 * LONG, 6 * (SHORT + SHORT - 1), err)) return -1;
  uint32_t start[ROWS];
  uint32_t v = 0;
  for (int r = 0; r < ROWS; r++) {
    int is_long = r % 2;
    start[r] = v;
    for (int j = 0; j < (is_long ? LONG : SHORT); j++, v++) {
      m->pos[3 * v] = (j + (is_long ? 0 : 0.5)) / (LONG - 1);
      m->pos[3 * v + 1] = (double)r / (ROWS - 1);
      m->pos[3 * v + 2] = 0;
    }
  }
  uint32_t *t = m->tris;
  for (int r = 0; r + 1 < ROWS; r++) {
    int long_below = r % 2;
    uint32_t L = start[long_below ? r : r + 1], S = start[long_below ? r + 1 : r];
    for (uint32_t j = 0; j < SHORT; j++) {
      uint32_t a[3] = {L + j, L + j + 1, S + j}, b[3] = {S + j, L + j + 1, L + j};
      memcpy(t, long_below ? a : b, sizeof a);
      t += 3;
    }
    for (uint32_t j = 0; j + 1 < SHORT; j++) {
      uint32_t a[3] = {S + j, L + j + 1, S + j + 1}, b[3] = {S + j, S + j + 1, L + j + 1};
      memcpy(t, long_below ? a : b, sizeof a);
      t += 3;
    }
  }
  return 0;
}

/* Pole, rings, pole. Each quad is split along its shorter diagonal; the whole
 * mesh is flipped at the end if the sweep direction made it inward. */
static int build_sweep(mesh_t *m, const organ_t *o, verr_t *err) {
  const uint32_t R = (uint32_t)o->rings, S = (uint32_t)o->segs;
  if (mesh_alloc(m, 2 + (size_t)R * S, 2 * (size_t)R * S, err)) return -1;
  const uint32_t last = 1 + R * S;
  o->surf(0, 0, m->pos);
  o->surf(PI, 0, m->pos + 3 * (size_t)last);
  for (uint32_t i = 0; i < R; i++)
    for (uint32_t j = 0; j < S; j++)
      o->surf(PI * (i + 1) / (R + 1), 2 * PI * j / S, m->pos + 3 * (size_t)(1 + i * S + j));
  uint32_t *t = m->tris;
  for (uint32_t j = 0; j < S; j++) {
    uint32_t j1 = (j + 1) % S;
    uint32_t first[3] = {0, 1 + j1, 1 + j};
    uint32_t end[3] = {last, 1 + (R - 1) * S + j, 1 + (R - 1) * S + j1};
    memcpy(t, first, sizeof first);
    memcpy(t + 3, end, sizeof end);
    t += 6;
  }
  for (uint32_t i = 0; i + 1 < R; i++)
    for (uint32_t j = 0; j < S; j++) {
      uint32_t j1 = (j + 1) % S;
      uint32_t a = 1 + i * S + j, b = 1 + i * S + j1, c = 1 + (i + 1) * S + j1, d = 1 + (i + 1) * S + j;
      double ac = v3_dist(m->pos + 3 * (size_t)a, m->pos + 3 * (size_t)c);
      double bd = v3_dist(m->pos + 3 * (size_t)b, m->pos + 3 * (size_t)d);
      uint32_t q[6] = {a, b, c, a, c, d}, q2[6] = {a, b, d, b, c, d};
      memcpy(t, ac <= bd ? q : q2, sizeof q);
      t += 6;
    }
  if (mesh_signed_volume(m) < 0)
    for (size_t k = 0; k < m->ntris; k++) {
      uint32_t x = m->tris[3 * k + 1];
      m->tris[3 * k + 1] = m->tris[3 * k + 2];
      m->tris[3 * k + 2] = x;
    }
  return 0;
}

/* Scales each axis to the target size (positive factors keep the surface
 * embedded and its orientation), puts the lowest point at z = 0 centred in x,y,
 * and rounds to float: the importer keeps no more, so the file claims no
 * precision the server will not see. */
static void place(mesh_t *m, const double size[3]) {
  double lo[3], hi[3];
  mesh_bounds(m, lo, hi);
  for (size_t v = 0; v < m->nverts; v++)
    for (int k = 0; k < 3; k++) {
      double ext = hi[k] - lo[k];
      double s = ext > 0 ? size[k] / ext : 1;
      double x = (m->pos[3 * v + k] - (k == 2 ? lo[k] : 0.5 * (lo[k] + hi[k]))) * s;
      m->pos[3 * v + k] = (float)x;
    }
}

/* Numbers vertices by first use in the triangle list, the order mesh_import
 * produces, so importing the file gives back this mesh vertex for vertex. */
static int renumber_first_use(mesh_t *m, verr_t *err) {
  uint32_t *id = malloc(m->nverts * sizeof *id);
  double *pos = malloc(3 * m->nverts * sizeof *pos);
  if (!id || !pos) {
    free(id);
    free(pos);
    return verr_set(err, "out of memory renumbering %zu vertices", m->nverts);
  }
  memset(id, 0xff, m->nverts * sizeof *id);
  uint32_t n = 0;
  for (size_t c = 0; c < 3 * m->ntris; c++) {
    uint32_t v = m->tris[c];
    if (id[v] == UINT32_MAX) {
      id[v] = n;
      memcpy(pos + 3 * (size_t)n, m->pos + 3 * (size_t)v, 3 * sizeof *pos);
      n++;
    }
    m->tris[c] = id[v];
  }
  free(m->pos);
  free(id);
  m->pos = pos;
  if (n != m->nverts) return verr_set(err, "%zu vertices are unused", m->nverts - n);
  return 0;
}

/* The generator refuses to write a mesh its own checker finds fault with. */
static int verify(const organ_t *o, const mesh_t *m, mesh_report_t *r, verr_t *err) {
  if (mesh_check(m, r)) return verr_set(err, "%s: out of memory checking the mesh", o->name);
  int open_patch = o->surf == NULL;
  if (r->nonmanifold_edges || r->inconsistent_edges || r->degenerate_faces || r->duplicate_vertices ||
      r->unreferenced_vertices || r->components != 1 || r->nonfinite_vertices || r->bad_index_faces)
    return verr_set(err, "%s: generated mesh has problems (run viscera-asset info on it)", o->name);
  if (!open_patch && (!r->closed || !(r->volume > 0)))
    return verr_set(err, "%s: generated mesh is not closed with positive volume", o->name);
  if (open_patch && r->boundary_edges == 0) return verr_set(err, "%s: patch unexpectedly closed", o->name);
  return 0;
}

static int make_organ(const organ_t *o, const char *dir, mesh_report_t *r, verr_t *err) {
  mesh_t m;
  if ((o->surf ? build_sweep(&m, o, err) : build_tissue(&m, err))) return -1;
  place(&m, o->size);
  char path[4096];
  int rc = renumber_first_use(&m, err);
  if (!rc) rc = verify(o, &m, r, err);
  if (!rc && snprintf(path, sizeof path, "%s/%s.obj", dir, o->name) >= (int)sizeof path)
    rc = verr_set(err, "%s: output path too long", dir);
  if (!rc) {
    char comment[256];
    snprintf(comment, sizeof comment, "%s; metres, z up; written by viscera-organ-gen, do not edit", o->about);
    rc = mesh_write_obj(&m, path, comment, err);
  }
  mesh_free(&m);
  return rc;
}

static void usage(FILE *f) {
  fprintf(f, "usage: viscera-organ-gen OUTDIR\n"
             "Writes tissue_block, spleen, kidney, gallbladder and liver_large (.obj, metres, z up)\n"
             "into OUTDIR (created if missing) and prints their sizes. The repository copies live\n"
             "in assets/meshes/; regenerate them with this tool rather than editing them.\n");
}

int main(int argc, char **argv) {
  if (argc == 2 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"))) {
    usage(stdout);
    return 0;
  }
  if (argc != 2 || argv[1][0] == '-') {
    usage(stderr);
    return 2;
  }
  const char *dir = argv[1];
  if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
    fprintf(stderr, "viscera-organ-gen: %s: cannot create directory: %s\n", dir, strerror(errno));
    return 1;
  }
  printf("%-14s %9s %10s   %s\n", "name", "vertices", "triangles", "size (m)");
  for (size_t i = 0; i < sizeof ORGANS / sizeof ORGANS[0]; i++) {
    mesh_report_t r;
    verr_t err = {{0}};
    if (make_organ(&ORGANS[i], dir, &r, &err)) {
      fprintf(stderr, "viscera-organ-gen: %s\n", err.msg);
      return 1;
    }
    printf("%-14s %9zu %10zu   %.4f x %.4f x %.4f%s\n", ORGANS[i].name, r.vertices, r.triangles, r.size[0], r.size[1],
           r.size[2], r.closed ? "" : "  (open patch)");
  }
  return 0;
}
