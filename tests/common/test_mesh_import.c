/* SPDX-License-Identifier: Apache-2.0 */
/* mesh_import: the same solid written as OBJ, STL and PLY imports to the same
 * welded mesh; every kind of bad input fails with a message naming the file. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "mesh.h"
#include "mesh_check.h"
#include "mesh_import.h"

static char dir[256];

static const char *tmp_path(const char *name) {
  static char buf[4][512];
  static int k;
  k = (k + 1) % 4;
  snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
  return buf[k];
}

static const char *write_file(const char *name, const char *text) {
  const char *p = tmp_path(name);
  FILE *f = fopen(p, "wb");
  if (!f) {
    perror(p);
    exit(1);
  }
  fputs(text, f);
  fclose(f);
  return p;
}

/* Unit cube [0,1]^3. Corner i has x = i&1, y = i>>1&1, z = i>>2&1. */
static const int CUBE_QUADS[6][4] = {
    {0, 2, 3, 1}, /* z = 0, normal -z */
    {4, 5, 7, 6}, /* z = 1, +z */
    {0, 1, 5, 4}, /* y = 0, -y */
    {2, 6, 7, 3}, /* y = 1, +y */
    {0, 4, 6, 2}, /* x = 0, -x */
    {1, 3, 7, 5}, /* x = 1, +x */
};
static const double QUAD_NORMALS[6][3] = {{0, 0, -1}, {0, 0, 1}, {0, -1, 0}, {0, 1, 0}, {-1, 0, 0}, {1, 0, 0}};

static void corner(int i, double p[3]) {
  p[0] = i & 1;
  p[1] = i >> 1 & 1;
  p[2] = i >> 2 & 1;
}

/* OBJ with one normal per face: assimp keeps 24 vertices until the weld. */
static const char *write_cube_obj(const char *name) {
  const char *p = tmp_path(name);
  FILE *f = fopen(p, "w");
  fprintf(f, "# cube\no cube\n");
  for (int i = 0; i < 8; i++) {
    double c[3];
    corner(i, c);
    fprintf(f, "v %g %g %g\n", c[0], c[1], c[2]);
  }
  for (int q = 0; q < 6; q++) fprintf(f, "vn %g %g %g\n", QUAD_NORMALS[q][0], QUAD_NORMALS[q][1], QUAD_NORMALS[q][2]);
  for (int q = 0; q < 6; q++) {
    const int *c = CUBE_QUADS[q];
    fprintf(f, "f %d//%d %d//%d %d//%d\n", c[0] + 1, q + 1, c[1] + 1, q + 1, c[2] + 1, q + 1);
    fprintf(f, "f %d//%d %d//%d %d//%d\n", c[0] + 1, q + 1, c[2] + 1, q + 1, c[3] + 1, q + 1);
  }
  fclose(f);
  return p;
}

/* ASCII STL repeats every corner: 36 vertices before the weld. */
static const char *write_cube_stl(const char *name) {
  const char *p = tmp_path(name);
  FILE *f = fopen(p, "w");
  fprintf(f, "solid cube\n");
  for (int q = 0; q < 6; q++) {
    const int *c = CUBE_QUADS[q];
    const int tri[2][3] = {{c[0], c[1], c[2]}, {c[0], c[2], c[3]}};
    for (int t = 0; t < 2; t++) {
      fprintf(f, "facet normal %g %g %g\nouter loop\n", QUAD_NORMALS[q][0], QUAD_NORMALS[q][1], QUAD_NORMALS[q][2]);
      for (int k = 0; k < 3; k++) {
        double v[3];
        corner(tri[t][k], v);
        fprintf(f, "vertex %g %g %g\n", v[0], v[1], v[2]);
      }
      fprintf(f, "endloop\nendfacet\n");
    }
  }
  fprintf(f, "endsolid cube\n");
  fclose(f);
  return p;
}

/* ASCII PLY with quads and a vertex per face corner: tests both the
 * triangulation and the weld. */
static const char *write_cube_ply(const char *name) {
  const char *p = tmp_path(name);
  FILE *f = fopen(p, "w");
  fprintf(f, "ply\nformat ascii 1.0\nelement vertex 24\nproperty float x\nproperty float y\nproperty float z\n"
             "property float nx\nproperty float ny\nproperty float nz\n"
             "element face 6\nproperty list uchar int vertex_indices\nend_header\n");
  for (int q = 0; q < 6; q++)
    for (int k = 0; k < 4; k++) {
      double v[3];
      corner(CUBE_QUADS[q][k], v);
      fprintf(f, "%g %g %g %g %g %g\n", v[0], v[1], v[2], QUAD_NORMALS[q][0], QUAD_NORMALS[q][1], QUAD_NORMALS[q][2]);
    }
  for (int q = 0; q < 6; q++) fprintf(f, "4 %d %d %d %d\n", 4 * q, 4 * q + 1, 4 * q + 2, 4 * q + 3);
  fclose(f);
  return p;
}

static void check_unit_cube(const char *path) {
  mesh_t m;
  verr_t err = {{0}};
  int rc = mesh_import(path, &m, &err);
  CHECK(rc == 0);
  if (rc) {
    fprintf(stderr, "%s\n", err.msg);
    return;
  }
  CHECK(m.nverts == 8);
  CHECK(m.ntris == 12);
  mesh_report_t r;
  CHECK(mesh_check(&m, &r) == 0);
  CHECK(r.closed);
  CHECK(r.duplicate_vertices == 0);
  CHECK(r.inconsistent_edges == 0);
  CHECK(r.components == 1);
  CHECK_NEAR(r.volume, 1.0, 1e-12);
  CHECK_NEAR(r.size[0] + r.size[1] + r.size[2], 3.0, 1e-12);
  CHECK(mesh_report_problems(&r) == 0);
  mesh_free(&m);
}

/* The header promises import(write_obj(import(f))) == import(f), exactly. */
static void check_round_trip(const char *path) {
  mesh_t a, b;
  verr_t err = {{0}};
  CHECK(mesh_import(path, &a, &err) == 0);
  const char *again = tmp_path("round_trip.obj");
  CHECK(mesh_write_obj(&a, again, "round trip", &err) == 0);
  CHECK(mesh_import(again, &b, &err) == 0);
  CHECK(a.nverts == b.nverts && a.ntris == b.ntris);
  if (a.nverts == b.nverts && a.ntris == b.ntris) {
    CHECK(memcmp(a.pos, b.pos, 3 * a.nverts * sizeof *a.pos) == 0);
    CHECK(memcmp(a.tris, b.tris, 3 * a.ntris * sizeof *a.tris) == 0);
  }
  mesh_free(&a);
  mesh_free(&b);
}

/* Two objects in one file merge into one mesh of two pieces; the unused
 * vertex is dropped. */
static void check_merge(void) {
  const char *p = write_file("two.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 9 9 9\n"
                                        "o first\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
                                        "v 5 0 0\nv 6 0 0\nv 5 1 0\nv 5 0 1\n"
                                        "o second\nf 6 8 7\nf 6 7 9\nf 6 9 8\nf 7 8 9\n");
  mesh_t m;
  verr_t err = {{0}};
  CHECK(mesh_import(p, &m, &err) == 0);
  CHECK(m.nverts == 8);
  CHECK(m.ntris == 8);
  mesh_report_t r;
  CHECK(mesh_check(&m, &r) == 0);
  CHECK(r.components == 2);
  CHECK(r.closed);
  CHECK(r.unreferenced_vertices == 0);
  CHECK_NEAR(r.volume, 2.0 / 6.0, 1e-12);
  CHECK_NEAR(r.bmax[0], 6.0, 0);
  mesh_free(&m);
}

/* A node transform (COLLADA <translate>) must be applied to the vertices. */
static void check_node_transform(void) {
  const char *p = write_file(
      "moved.dae",
      "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
      "<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n"
      "<asset><unit name=\"meter\" meter=\"1\"/><up_axis>Y_UP</up_axis></asset>\n"
      "<library_geometries><geometry id=\"tri\"><mesh>\n"
      "<source id=\"pos\"><float_array id=\"pos-a\" count=\"9\">0 0 0 1 0 0 0 1 0</float_array>\n"
      "<technique_common><accessor source=\"#pos-a\" count=\"3\" stride=\"3\">\n"
      "<param name=\"X\" type=\"float\"/><param name=\"Y\" type=\"float\"/><param name=\"Z\" type=\"float\"/>\n"
      "</accessor></technique_common></source>\n"
      "<vertices id=\"vtx\"><input semantic=\"POSITION\" source=\"#pos\"/></vertices>\n"
      "<triangles count=\"1\"><input semantic=\"VERTEX\" source=\"#vtx\" offset=\"0\"/><p>0 1 2</p></triangles>\n"
      "</mesh></geometry></library_geometries>\n"
      "<library_visual_scenes><visual_scene id=\"s\"><node id=\"n\"><translate>10 0 0</translate>\n"
      "<instance_geometry url=\"#tri\"/></node></visual_scene></library_visual_scenes>\n"
      "<scene><instance_visual_scene url=\"#s\"/></scene>\n"
      "</COLLADA>\n");
  mesh_t m;
  verr_t err = {{0}};
  int rc = mesh_import(p, &m, &err);
  CHECK(rc == 0);
  if (rc) {
    fprintf(stderr, "%s\n", err.msg);
    return;
  }
  CHECK(m.nverts == 3 && m.ntris == 1);
  double lo[3], hi[3];
  mesh_bounds(&m, lo, hi);
  CHECK_NEAR(lo[0], 10.0, 1e-6);
  CHECK_NEAR(hi[0], 11.0, 1e-6);
  mesh_free(&m);
}

/* Each failure leaves the mesh empty and names the file. */
static void expect_fail(const char *path, const mesh_import_opts_t *opts, const char *also) {
  mesh_t m;
  verr_t err = {{0}};
  int rc = mesh_import_ex(path, opts, &m, &err);
  CHECK(rc == -1);
  CHECK(m.nverts == 0 && m.ntris == 0 && m.pos == NULL && m.tris == NULL);
  CHECK(strstr(err.msg, path) != NULL);
  if (also) CHECK(strstr(err.msg, also) != NULL);
  printf("  expected failure: %s\n", err.msg);
  if (rc == 0) mesh_free(&m);
}

static void test_bad_inputs(const char *cube_obj) {
  expect_fail(tmp_path("missing.obj"), NULL, "No such file");
  expect_fail(write_file("empty.obj", ""), NULL, "empty");
  expect_fail(dir, NULL, "not a regular file");
  /* Fixed-seed noise: the same bytes every run. */
  unsigned char noise[4096];
  uint32_t s = 12345;
  for (size_t i = 0; i < sizeof noise; i++) {
    s = s * 1664525u + 1013904223u;
    noise[i] = (unsigned char)(s >> 24);
  }
  const char *names[] = {"garbage.obj", "garbage.stl", "garbage.ply", "garbage.bin"};
  for (int i = 0; i < 4; i++) {
    const char *p = tmp_path(names[i]);
    FILE *f = fopen(p, "wb");
    fwrite(noise, 1, sizeof noise, f);
    fclose(f);
    expect_fail(p, NULL, NULL);
  }
  expect_fail(write_file("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 nan 0\nv 0 0 1\nf 1 2 4\nf 1 3 2\n"), NULL, "vertex");
  expect_fail(write_file("nan_first.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), NULL, "non-finite");
  expect_fail(write_file("inf.obj", "v 1e39 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), NULL, "non-finite");
  expect_fail(write_file("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\n"), NULL, "no triangles");
  expect_fail(write_file("lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\n"), NULL, "no triangles");
  expect_fail(write_file("vertices_only.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"), NULL, NULL);
  expect_fail(write_file("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n"), NULL, NULL);

  mesh_import_opts_t o = mesh_import_default_opts();
  o.max_triangles = 11;
  expect_fail(cube_obj, &o, "too large");
  o = mesh_import_default_opts();
  o.max_file_bytes = 16;
  expect_fail(cube_obj, &o, "too large");
  o.max_file_bytes = 1 << 20;
  mesh_t m;
  verr_t err = {{0}};
  CHECK(mesh_import_ex(cube_obj, &o, &m, &err) == 0);
  mesh_free(&m);
}

int main(void) {
  const char *base = getenv("TMPDIR");
  snprintf(dir, sizeof dir, "%s/viscera_import_XXXXXX", base && *base ? base : "/tmp");
  if (!mkdtemp(dir)) {
    perror("mkdtemp");
    return 1;
  }
  /* tmp_path() reuses its buffers, so keep this one. */
  char obj[512];
  snprintf(obj, sizeof obj, "%s", write_cube_obj("cube.obj"));
  check_unit_cube(obj);
  check_unit_cube(write_cube_stl("cube.stl"));
  check_unit_cube(write_cube_ply("cube.ply"));
  check_round_trip(obj);
  check_round_trip(tmp_path("cube.stl"));
  check_merge();
  check_node_transform();
  test_bad_inputs(obj);

  /* Leave nothing behind in the temp dir. */
  const char *left[] = {"cube.obj",    "cube.stl",          "cube.ply",      "round_trip.obj", "two.obj",
                        "moved.dae",   "empty.obj",         "garbage.obj",   "garbage.stl",    "garbage.ply",
                        "garbage.bin", "nan.obj",           "nan_first.obj", "inf.obj",        "points.obj",
                        "lines.obj",   "vertices_only.obj", "bad_index.obj"};
  for (size_t i = 0; i < sizeof left / sizeof left[0]; i++) unlink(tmp_path(left[i]));
  CHECK(rmdir(dir) == 0);
  return check_report("test_mesh_import");
}
