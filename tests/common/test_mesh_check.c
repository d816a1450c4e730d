/* SPDX-License-Identifier: Apache-2.0 */
/* mesh_check on meshes whose answers are known by construction, then on the
 * generated assets in assets/meshes (the ones the scenes use). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_assets.h"
#include "mesh.h"
#include "mesh_check.h"
#include "mesh_import.h"

static void make(mesh_t *m, size_t nv, const double *pos, size_t nt, const uint32_t *tris) {
  verr_t err;
  if (mesh_alloc(m, nv, nt, &err)) {
    fprintf(stderr, "%s\n", err.msg);
    exit(1);
  }
  memcpy(m->pos, pos, 3 * nv * sizeof *pos);
  memcpy(m->tris, tris, 3 * nt * sizeof *tris);
}

/* Unit cube, corner i at (i&1, i>>1&1, i>>2&1), outward. */
static const uint32_t CUBE_TRIS[36] = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                                       2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};

static void make_cube(mesh_t *m, double scale) {
  double pos[24];
  for (int i = 0; i < 8; i++) {
    pos[3 * i] = scale * (i & 1);
    pos[3 * i + 1] = scale * (i >> 1 & 1);
    pos[3 * i + 2] = scale * (i >> 2 & 1);
  }
  make(m, 8, pos, 12, CUBE_TRIS);
}

static int printed_contains(const mesh_report_t *r, const char *text) {
  FILE *f = tmpfile();
  if (!f) return 0;
  mesh_report_print(r, f);
  rewind(f);
  char buf[4096];
  size_t n = fread(buf, 1, sizeof buf - 1, f);
  buf[n] = 0;
  fclose(f);
  return strstr(buf, text) != NULL;
}

static void test_cube(void) {
  mesh_t m;
  mesh_report_t r;
  make_cube(&m, 1);
  CHECK(mesh_check(&m, &r) == 0);
  CHECK(r.vertices == 8 && r.triangles == 12);
  CHECK(r.edges == 18);
  CHECK(r.closed);
  CHECK(r.boundary_edges == 0 && r.nonmanifold_edges == 0 && r.inconsistent_edges == 0);
  CHECK(r.degenerate_faces == 0 && r.duplicate_vertices == 0 && r.unreferenced_vertices == 0);
  CHECK(r.components == 1);
  CHECK(r.euler == 2);
  CHECK_NEAR(r.volume, 1.0, 1e-12);
  CHECK_NEAR(r.size[0], 1.0, 0);
  CHECK_NEAR(r.bmin[2], 0.0, 0);
  CHECK_NEAR(r.min_angle_deg, 45.0, 1e-9);
  CHECK(mesh_report_problems(&r) == 0);
  CHECK(printed_contains(&r, "no problems found"));
  CHECK(printed_contains(&r, "genus 0"));

  /* All faces flipped: still closed, but the volume says inward. */
  for (size_t t = 0; t < m.ntris; t++) {
    uint32_t x = m.tris[3 * t];
    m.tris[3 * t] = m.tris[3 * t + 1];
    m.tris[3 * t + 1] = x;
  }
  CHECK(mesh_check(&m, &r) == 0);
  CHECK(r.closed && r.inconsistent_edges == 0);
  CHECK_NEAR(r.volume, -1.0, 1e-12);
  CHECK(mesh_report_problems(&r) == 1);
  CHECK(printed_contains(&r, "inward"));

  /* Flip one back: its three edges now disagree with their neighbours. */
  uint32_t x = m.tris[0];
  m.tris[0] = m.tris[1];
  m.tris[1] = x;
  CHECK(mesh_check(&m, &r) == 0);
  CHECK(r.inconsistent_edges == 3);
  CHECK(printed_contains(&r, "3 edges whose two faces are oriented inconsistently"));
  mesh_free(&m);

  /* The degenerate test is relative: a micrometre cube and a kilometre cube are fine. */
  double scales[] = {1e-6, 1e3};
  for (int i = 0; i < 2; i++) {
    make_cube(&m, scales[i]);
    CHECK(mesh_check(&m, &r) == 0);
    CHECK(r.degenerate_faces == 0);
    CHECK_NEAR(r.volume, scales[i] * scales[i] * scales[i], 1e-9 * scales[i] * scales[i] * scales[i]);
    mesh_free(&m);
  }
}

/* nx x ny quads, each split in two: boundary 2 (nx + ny), a disk (euler 1). */
static void test_open_grid(void) {
  enum { NX = 5, NY = 3 };
  double pos[3 * (NX + 1) * (NY + 1)];
  uint32_t tris[6 * NX * NY];
  for (int j = 0; j <= NY; j++)
    for (int i = 0; i <= NX; i++) {
      double *p = pos + 3 * (j * (NX + 1) + i);
      p[0] = i;
      p[1] = j;
      p[2] = 0.1 * i * j;
    }
  uint32_t *t = tris;
  for (uint32_t j = 0; j < NY; j++)
    for (uint32_t i = 0; i < NX; i++) {
      uint32_t a = j * (NX + 1) + i, b = a + 1, c = a + NX + 2, d = a + NX + 1;
      uint32_t q[6] = {a, b, c, a, c, d};
      memcpy(t, q, sizeof q);
      t += 6;
    }
  mesh_t m;
  mesh_report_t r;
  make(&m, (NX + 1) * (NY + 1), pos, 2 * NX * NY, tris);
  CHECK(mesh_check(&m, &r) == 0);
  CHECK(!r.closed);
  CHECK(r.boundary_edges == 2 * (NX + NY));
  CHECK(r.nonmanifold_edges == 0 && r.inconsistent_edges == 0 && r.degenerate_faces == 0);
  CHECK(r.euler == 1);
  CHECK(r.components == 1);
  CHECK(mesh_report_problems(&r) == 1);
  CHECK(printed_contains(&r, "16 boundary edges"));
  CHECK(printed_contains(&r, "undefined (surface not closed)"));
  mesh_free(&m);
}

/* Three triangles on one edge, a zero-area sliver, a repeated index, a
 * duplicate position, an unused vertex, a bad index and a NaN: each counted. */
static void test_broken(void) {
  const double pos[] = {
      0,   0, 0, 1, 0,  0,          /* 0, 1: the shared edge */
      0,   1, 0, 0, -1, 0, 0, 0, 1, /* 2, 3, 4: three wings */
      2,   0, 0, 3, 0,  0, 4, 0, 0, /* 5, 6, 7: collinear */
      0,   1, 0,                    /* 8: same position as 2 */
      9,   9, 9,                    /* 9: used by nothing */
      NAN, 0, 0,                    /* 10: only in the bad-index face */
  };
  const uint32_t tris[] = {
      0,  1, 2,  1, 0, 3, 0, 1, 4, /* non-manifold edge 0-1 */
      5,  6, 7,                    /* collinear: zero area */
      3,  3, 4,                    /* repeated index */
      8,  6, 5,                    /* uses the duplicate */
      10, 5, 42,                   /* index out of range */
  };
  mesh_t m;
  mesh_report_t r;
  make(&m, 11, pos, 7, tris);
  CHECK(mesh_check(&m, &r) == 0);
  CHECK(r.nonmanifold_edges == 1);
  CHECK(!r.closed);
  CHECK(r.degenerate_faces == 2);
  CHECK(r.duplicate_vertices == 1);
  CHECK(r.unreferenced_vertices == 2); /* 9, and 10 whose only face is invalid */
  CHECK(r.bad_index_faces == 1);
  CHECK(r.nonfinite_vertices == 1);
  CHECK(r.components == 2); /* the wings; 5,6,7,8 */
  CHECK(printed_contains(&r, "1 non-manifold edges"));
  CHECK(printed_contains(&r, "2 degenerate faces"));
  CHECK(printed_contains(&r, "problems found:"));
  mesh_free(&m);

  /* A sliver is degenerate when its height is below 1e-6 of its length... */
  const double sliver[] = {0, 0, 0, 1, 0, 0, 0.5, 1e-8, 0};
  const uint32_t one[] = {0, 1, 2};
  make(&m, 3, sliver, 1, one);
  CHECK(mesh_check(&m, &r) == 0);
  CHECK(r.degenerate_faces == 1);
  mesh_free(&m);
  /* ...and a thin but honest triangle is not. */
  const double thin[] = {0, 0, 0, 1, 0, 0, 0.5, 1e-4, 0};
  make(&m, 3, thin, 1, one);
  CHECK(mesh_check(&m, &r) == 0);
  CHECK(r.degenerate_faces == 0);
  CHECK_NEAR(r.min_angle_deg, atan(2e-4) * 180 / M_PI, 1e-9);
  CHECK(r.boundary_edges == 3 && r.euler == 1);
  mesh_free(&m);
}

/* Two tetrahedra apart, and a torus: components and euler characteristic. */
static void test_topology(void) {
  const double pos[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 5, 0, 0, 6, 0, 0, 5, 1, 0, 5, 0, 1};
  const uint32_t tris[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3, 4, 6, 5, 4, 5, 7, 4, 7, 6, 5, 6, 7};
  mesh_t m;
  mesh_report_t r;
  make(&m, 8, pos, 8, tris);
  CHECK(mesh_check(&m, &r) == 0);
  CHECK(r.closed && r.components == 2 && r.euler == 4);
  CHECK_NEAR(r.volume, 2.0 / 6.0, 1e-12);
  CHECK(printed_contains(&r, "2 separate connected pieces"));
  mesh_free(&m);

  enum { U = 12, V = 8 };
  double tp[3 * U * V];
  uint32_t tt[6 * U * V], *t = tt;
  for (int i = 0; i < U; i++)
    for (int j = 0; j < V; j++) {
      double a = 2 * M_PI * i / U, b = 2 * M_PI * j / V;
      tp[3 * (i * V + j)] = (3 + cos(b)) * cos(a);
      tp[3 * (i * V + j) + 1] = (3 + cos(b)) * sin(a);
      tp[3 * (i * V + j) + 2] = sin(b);
    }
  for (uint32_t i = 0; i < U; i++)
    for (uint32_t j = 0; j < V; j++) {
      uint32_t a = i * V + j, b = ((i + 1) % U) * V + j, c = ((i + 1) % U) * V + (j + 1) % V, d = i * V + (j + 1) % V;
      uint32_t q[6] = {a, b, c, a, c, d};
      memcpy(t, q, sizeof q);
      t += 6;
    }
  make(&m, U * V, tp, 2 * U * V, tt);
  CHECK(mesh_check(&m, &r) == 0);
  CHECK(r.closed && r.components == 1 && r.euler == 0 && r.inconsistent_edges == 0);
  CHECK(fabs(r.volume) > 10); /* 2 pi^2 R r^2 = 59 for the smooth torus */
  CHECK(printed_contains(&r, "genus 1"));
  mesh_free(&m);
}

/* Largest coordinate difference of two meshes with equal triangles, or -1
 * when their sizes or triangles differ. */
static double mesh_distance(const mesh_t *a, const mesh_t *b) {
  if (a->nverts != b->nverts || a->ntris != b->ntris) return -1;
  if (memcmp(a->tris, b->tris, 3 * a->ntris * sizeof *a->tris)) return -1;
  double d = 0;
  for (size_t i = 0; i < 3 * a->nverts; i++) d = fmax(d, fabs(a->pos[i] - b->pos[i]));
  return d;
}

/* Reads the "v x y z" and "f a b c" lines of a file as written, without
 * assimp, to compare the importer against. */
static int read_plain_obj(const char *path, mesh_t *m) {
  FILE *f = fopen(path, "r");
  if (!f) return -1;
  size_t nv = 0, nt = 0;
  char line[256];
  while (fgets(line, sizeof line, f)) {
    nv += !strncmp(line, "v ", 2);
    nt += !strncmp(line, "f ", 2);
  }
  verr_t err;
  if (mesh_alloc(m, nv, nt, &err)) {
    fclose(f);
    return -1;
  }
  rewind(f);
  size_t v = 0, t = 0;
  int ok = 1;
  while (ok && fgets(line, sizeof line, f)) {
    if (!strncmp(line, "v ", 2)) {
      double *p = m->pos + 3 * v++;
      ok = sscanf(line + 2, "%lf %lf %lf", p, p + 1, p + 2) == 3;
    } else if (!strncmp(line, "f ", 2)) {
      uint32_t *q = m->tris + 3 * t++;
      ok = sscanf(line + 2, "%u %u %u", q, q + 1, q + 2) == 3 && q[0] && q[1] && q[2];
      for (int k = 0; k < 3; k++) q[k]--; /* OBJ counts from 1 */
    }
  }
  fclose(f);
  if (!ok) mesh_free(m);
  return ok ? 0 : -1;
}

/* The generated assets: counts, sizes and placement as organ_gen.c promises. */
typedef struct expect {
  const char *name;
  size_t verts, tris;
  double size[3];
  int open;
} expect_t;

static void test_assets(void) {
  const char *src = getenv("VISCERA_SOURCE_DIR");
  CHECK(src != NULL);
  if (!src) return;
  const expect_t E[] = {
      {"tissue_block", 45, 66, {0.10, 0.06, 0}, 1},         {"spleen", 600, 1196, {0.12, 0.07, 0.04}, 0},
      {"kidney", 2000, 3996, {0.11, 0.06, 0.035}, 0},       {"gallbladder", 5400, 10782, {0.09, 0.035, 0.035}, 0},
      {"liver_large", 23522, 47040, {0.20, 0.14, 0.10}, 0},
  };
  for (size_t i = 0; i < sizeof E / sizeof E[0]; i++) {
    char name[64];
    snprintf(name, sizeof name, "meshes/%s.obj", E[i].name);
    const char *path = test_asset(name);
    mesh_t m;
    int rc = test_mesh_load(name + 7, &m); /* prints why it failed */
    CHECK(rc == 0);
    if (rc) continue;
    /* The generator writes vertices in the importer's order: the server gets
     * the file vertex for vertex, to the float precision of assimp's parser. */
    mesh_t plain;
    CHECK(read_plain_obj(path, &plain) == 0);
    double d = mesh_distance(&plain, &m);
    CHECK(d >= 0 && d <= 1e-9);
    mesh_free(&plain);
    mesh_report_t r;
    CHECK(mesh_check(&m, &r) == 0);
    printf("%s: %zu vertices, %zu triangles, %.4f x %.4f x %.4f m\n", E[i].name, r.vertices, r.triangles, r.size[0],
           r.size[1], r.size[2]);
    CHECK(fabs((double)r.vertices - (double)E[i].verts) <= 0.02 * (double)E[i].verts);
    CHECK(fabs((double)r.triangles - (double)E[i].tris) <= 0.02 * (double)E[i].tris);
    for (int k = 0; k < 3; k++) CHECK_NEAR(r.size[k], E[i].size[k], 1e-6);
    CHECK_NEAR(r.bmin[2], 0.0, 1e-7);
    CHECK_NEAR(r.bmin[0] + r.bmax[0], 0.0, 1e-7);
    CHECK_NEAR(r.bmin[1] + r.bmax[1], 0.0, 1e-7);
    CHECK(r.nonmanifold_edges == 0 && r.inconsistent_edges == 0 && r.degenerate_faces == 0);
    CHECK(r.duplicate_vertices == 0 && r.unreferenced_vertices == 0 && r.components == 1);
    if (E[i].open) {
      /* The patch: a disk whose every face looks up (+z). */
      CHECK(!r.closed && r.boundary_edges > 0 && r.euler == 1);
      CHECK(mesh_report_problems(&r) == 1);
      size_t down = 0;
      for (size_t t = 0; t < m.ntris; t++) {
        const double *a = m.pos + 3 * m.tris[3 * t], *b = m.pos + 3 * m.tris[3 * t + 1],
                     *c = m.pos + 3 * m.tris[3 * t + 2];
        down += (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) <= 0;
      }
      CHECK(down == 0);
    } else {
      CHECK(r.closed && r.euler == 2 && r.volume > 0);
      /* An organ fills a fair part of its box; a folded or inside-out one would not. */
      double box = r.size[0] * r.size[1] * r.size[2];
      CHECK(r.volume > 0.25 * box && r.volume < 0.75 * box);
      CHECK(mesh_report_problems(&r) == 0);
    }
    mesh_free(&m);
  }
}

/* Nothing at all is a report, not a crash. */
static void test_empty(void) {
  mesh_t m = {0};
  mesh_report_t r;
  CHECK(mesh_check(&m, &r) == 0);
  CHECK(r.vertices == 0 && r.triangles == 0 && r.components == 0 && !r.closed);
  CHECK(mesh_report_problems(&r) == 1);
  CHECK(printed_contains(&r, "no triangles"));
}

int main(void) {
  test_empty();
  test_cube();
  test_open_grid();
  test_broken();
  test_topology();
  test_assets();
  return check_report("test_mesh_check");
}
