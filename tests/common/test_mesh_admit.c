/* SPDX-License-Identifier: Apache-2.0 */
/* test_mesh_admit: each mesh defect of issue 15 refused or repaired with a
 * message (common/mesh_admit.c): a clean cube passes untouched; inside out
 * and inconsistently wound cubes are repaired (outward, consistent); open,
 * non-manifold, two-part, degenerate, 1e30 m and 1e-30 m meshes are
 * refused naming the defect. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "mesh_admit.h"
#include "mesh_check.h"

static const double cube_v[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                    {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
/* Outward (counter-clockwise seen from outside). */
static const uint32_t cube_t[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                                       {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};

/* copies cubes (each shifted by 2 m in x) of edge `size` m; ntris_keep
 * triangles of each (12: all). */
static void cubes(mesh_t *m, int copies, double size, int ntris_keep) {
  verr_t e;
  CHECK(mesh_alloc(m, 8 * (size_t)copies, (size_t)ntris_keep * (size_t)copies, &e) == 0);
  for (int c = 0; c < copies; c++) {
    for (int i = 0; i < 8; i++)
      for (int k = 0; k < 3; k++) m->pos[3 * (8 * c + i) + k] = cube_v[i][k] * size + (k == 0 ? 2.0 * size * c : 0);
    for (int t = 0; t < ntris_keep; t++)
      for (int k = 0; k < 3; k++) m->tris[3 * (ntris_keep * c + t) + k] = cube_t[t][k] + 8 * (uint32_t)c;
  }
}

static const mesh_admit_opts_t closed = {0, MESH_ADMIT_MIN_SIZE, MESH_ADMIT_MAX_SIZE};
static const mesh_admit_opts_t sheet = {1, MESH_ADMIT_MIN_SIZE, MESH_ADMIT_MAX_SIZE};

/* mesh_admit fails with a message holding `part`. */
static int refused(mesh_t *m, const mesh_admit_opts_t *o, const char *part) {
  char note[200];
  verr_t e;
  int rc = mesh_admit(m, o, "m.obj", note, sizeof note, &e);
  mesh_free(m);
  if (rc == 0) {
    fprintf(stderr, "  accepted, wanted '%s'\n", part);
    return 0;
  }
  printf("  refused: %s\n", e.msg);
  return strstr(e.msg, "m.obj: ") == e.msg && strstr(e.msg, part) != NULL;
}

/* Admitted; its note holds `part` ("" = must be empty); afterwards closed,
 * consistent and outward. */
static int repaired(mesh_t *m, const char *part) {
  char note[200];
  verr_t e;
  int ok = mesh_admit(m, &closed, "m.obj", note, sizeof note, &e) == 0;
  if (!ok) fprintf(stderr, "  refused: %s\n", e.msg);
  printf("  note: '%s'\n", note);
  ok = ok && (part[0] ? strstr(note, part) != NULL : note[0] == '\0');
  mesh_report_t r;
  ok = ok && mesh_check(m, &r) == 0 && r.inconsistent_edges == 0 && r.closed && r.volume > 0;
  mesh_free(m);
  return ok;
}

int main(void) {
  mesh_t m;
  cubes(&m, 1, 0.05, 12);
  CHECK(repaired(&m, ""));
  /* Inside out: every triangle wound inward. */
  cubes(&m, 1, 0.05, 12);
  for (size_t t = 0; t < m.ntris; t++) {
    uint32_t c = m.tris[3 * t + 1];
    m.tris[3 * t + 1] = m.tris[3 * t + 2];
    m.tris[3 * t + 2] = c;
  }
  CHECK(repaired(&m, "inside out"));
  /* Inconsistent: three triangles wound the other way. */
  cubes(&m, 1, 0.05, 12);
  for (size_t t = 3; t < 12; t += 4) {
    uint32_t c = m.tris[3 * t + 1];
    m.tris[3 * t + 1] = m.tris[3 * t + 2];
    m.tris[3 * t + 2] = c;
  }
  CHECK(repaired(&m, "3 of 12 triangles re-wound"));
  /* Inconsistent and mostly inward: both repairs. */
  cubes(&m, 1, 0.05, 12);
  for (size_t t = 0; t < 12; t++)
    if (t != 5) {
      uint32_t c = m.tris[3 * t + 1];
      m.tris[3 * t + 1] = m.tris[3 * t + 2];
      m.tris[3 * t + 2] = c;
    }
  CHECK(repaired(&m, "re-wound"));
  /* Open: the last two triangles missing. A sheet model takes it. */
  cubes(&m, 1, 0.05, 10);
  CHECK(refused(&m, &closed, "open surface (4 boundary edge(s))"));
  cubes(&m, 1, 0.05, 10);
  {
    char note[200];
    verr_t e;
    CHECK(mesh_admit(&m, &sheet, "m.obj", note, sizeof note, &e) == 0);
    mesh_free(&m);
  }
  /* Two parts. */
  cubes(&m, 2, 0.05, 12);
  CHECK(refused(&m, &closed, "in 2 separate parts"));
  /* Non-manifold: a third triangle on the edge 0-1 (to a new vertex). */
  {
    verr_t e;
    mesh_t c;
    cubes(&c, 1, 0.05, 12);
    CHECK(mesh_alloc(&m, 9, 13, &e) == 0);
    memcpy(m.pos, c.pos, 24 * sizeof(double));
    memcpy(m.tris, c.tris, 36 * sizeof(uint32_t));
    m.pos[24] = 0.025, m.pos[25] = -0.05, m.pos[26] = -0.05;
    m.tris[36] = 0, m.tris[37] = 1, m.tris[38] = 8;
    mesh_free(&c);
    CHECK(refused(&m, &sheet, "non-manifold: 1 edge(s)"));
  }
  /* Degenerate: vertex 6 moved onto the segment 5-7 (triangles 4-5-6... keep
   * the mesh closed but one face of zero area). */
  cubes(&m, 1, 0.05, 12);
  m.tris[3 * 2 + 2] = m.tris[3 * 2 + 1]; /* repeated index */
  CHECK(refused(&m, &sheet, "degenerate"));
  /* Absurd sizes: 1e30 m and 1e-30 m across (the volume of the first
   * overflows in file units, the second underflows). */
  cubes(&m, 1, 1e30, 12);
  CHECK(refused(&m, &closed, "m across"));
  cubes(&m, 1, 1e-30, 12);
  CHECK(refused(&m, &closed, "outside 0.0001 .. 10 m"));
  cubes(&m, 1, 50, 12); /* a 50 mm cube written in millimetres */
  CHECK(refused(&m, &closed, "scale: 0.001"));
  /* Non-finite and empty (mesh_validate). */
  cubes(&m, 1, 0.05, 12);
  m.pos[4] = NAN;
  CHECK(refused(&m, &closed, "non-finite"));
  return check_report("test_mesh_admit");
}
