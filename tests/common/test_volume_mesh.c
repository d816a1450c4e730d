/* SPDX-License-Identifier: Apache-2.0 */
/* volume_mesh and tet_embed: tetrahedral meshes from files. Every format
 * written by the project's own writer (the asset tool's `tet --out`) reads
 * back exactly; hand-written files exercise what real exporters put in
 * them (other sections, tags that are not 1..n, lower-dimensional elements,
 * 1-based TetGen, VTK 5.1 offsets); every refusal names its line; the
 * boundary of a mesh is closed and outward; the embedding reproduces points
 * and finds the nearest tetrahedron for points outside. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "mesh.h"
#include "test_assets.h"
#include "test_tmpfile.h"
#include "tet_embed.h"
#include "tet_mesh.h"
#include "volume_mesh.h"

static int same_mesh(const tet_mesh_t *a, const tet_mesh_t *b) {
  return a->nnodes == b->nnodes && a->ntets == b->ntets && !memcmp(a->x, b->x, 3 * a->nnodes * sizeof(double)) &&
         !memcmp(a->tets, b->tets, 4 * a->ntets * sizeof(uint32_t));
}

static void round_trip(const tet_mesh_t *t, const char *what) {
  static const char *const ext[] = {"msh", "msh", "vtk", "node"};
  for (int f = 0; f < 4; f++) {
    char name[64];
    snprintf(name, sizeof name, "vol_%s_%d.%s", what, f, ext[f]);
    char path[256];
    snprintf(path, sizeof path, "%s", test_tmp_path(name));
    verr_t err = {{0}};
    CHECK(volume_export(t, (volume_format_t)f, path, &err) == 0);
    tet_mesh_t back;
    volume_report_t r;
    int rc = volume_import(path, &back, &r, &err);
    if (rc) fprintf(stderr, "%s: %s\n", path, err.msg);
    CHECK(rc == 0);
    if (!rc) {
      CHECK(same_mesh(t, &back));
      CHECK(r.flipped == 0 && r.unused == 0 && r.skipped == 0);
      tet_mesh_free(&back);
    }
    unlink(path);
    if (f == VOLUME_TETGEN) {
      path[strlen(path) - 4] = 0;
      strcat(path, "ele");
      unlink(path);
    }
  }
}

/* Imports `text` written to a file named `name`: 0 on success (the mesh
 * then in *t), else -1 with the message in *err. */
static int import_text(const char *name, const char *text, tet_mesh_t *t, volume_report_t *r, verr_t *err) {
  const char *path = test_write_tmp(name, text);
  char p[256];
  snprintf(p, sizeof p, "%s", path);
  int rc = volume_import(p, t, r, err);
  unlink(p);
  return rc;
}

/* The refusal of `text` must name `line` (0: a whole-file message) and
 * contain `words`. */
static void refused(const char *name, const char *text, int line, const char *words) {
  tet_mesh_t t;
  verr_t err = {{0}};
  int rc = import_text(name, text, &t, NULL, &err);
  CHECK(rc != 0);
  char at[32];
  snprintf(at, sizeof at, ":%d: ", line);
  int ok = rc != 0 && (line <= 0 || strstr(err.msg, at)) && strstr(err.msg, words);
  if (!ok) fprintf(stderr, "%s: want line %d and '%s', got: %s\n", name, line, words, rc ? err.msg : "(accepted)");
  CHECK(ok);
  if (!rc) tet_mesh_free(&t);
}

/* Two tetrahedra sharing a face, tags 10..50, one written inside out, a
 * node nobody uses (tag 60), a triangle and a point, other sections. */
static const char MSH2[] = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                           "$PhysicalNames\n1\n3 1 \"organ\"\n$EndPhysicalNames\n"
                           "$Nodes\n6\n10 0 0 0\n20 1 0 0\n30 0 1 0\n40 0 0 1\n50 1 1 1\n60 5 5 5\n$EndNodes\n"
                           "$Elements\n4\n1 15 2 0 1 10\n2 2 2 0 1 10 20 30\n"
                           "3 4 2 1 1 10 20 30 40\n4 4 2 1 1 20 40 30 50\n$EndElements\n";

static void hand_written(void) {
  tet_mesh_t t;
  volume_report_t r;
  verr_t err = {{0}};
  CHECK(import_text("vol_h.msh", MSH2, &t, &r, &err) == 0);
  CHECK(t.nnodes == 5 && t.ntets == 2);
  CHECK(r.unused == 1 && r.skipped == 2);
  CHECK(r.flipped == 1); /* 20 40 30 50 is inside out */
  CHECK_NEAR(r.volume, 1.0 / 6 + 1.0 / 3, 1e-12);
  for (size_t i = 0; i < t.ntets; i++) CHECK(tet_volume(&t, t.x, i) > 0);
  tet_mesh_free(&t);

  /* MSH 4.1: blocks by entity, tags listed before coordinates. */
  static const char MSH4[] = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
                             "$Entities\n0 0 0 1\n1 0 0 0 1 1 1 0 0\n$EndEntities\n"
                             "$Nodes\n2 5 1 5\n0 1 0 1\n1\n0 0 0\n3 1 0 4\n2\n3\n4\n5\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n"
                             "$EndNodes\n$Elements\n2 3 1 3\n2 1 2 1\n1 1 2 3\n3 1 4 2\n2 1 2 3 4\n3 2 4 3 5\n"
                             "$EndElements\n";
  CHECK(import_text("vol_h4.msh", MSH4, &t, &r, &err) == 0);
  CHECK(t.nnodes == 5 && t.ntets == 2 && r.skipped == 1 && r.flipped == 1);
  tet_mesh_free(&t);

  /* VTK 5.1 layout with a FIELD block before the points and a triangle. */
  static const char VTK51[] = "# vtk DataFile Version 5.1\ngmsh export\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                              "FIELD FieldData 1\nTIME 1 1 double\n0.5\n"
                              "POINTS 5 float\n0 0 0 1 0 0 0 1 0\n0 0 1 1 1 1\n"
                              "CELLS 4 11\nOFFSETS vtktypeint64\n0 4 8 11\nCONNECTIVITY vtktypeint64\n"
                              "0 1 2 3\n1 3 2 4\n0 1 2\nCELL_TYPES 3\n10\n10\n5\nPOINT_DATA 5\n";
  CHECK(import_text("vol_h51.vtk", VTK51, &t, &r, &err) == 0);
  CHECK(t.nnodes == 5 && t.ntets == 2 && r.skipped == 1);
  tet_mesh_free(&t);

  /* TetGen, numbered from 1, with attributes, markers and comments. */
  const char *node = test_write_tmp("vol_tg.node", "# made by hand\n5 3 1 1\n1 0 0 0 7 1\n2 1 0 0 7 1\n"
                                                   "3 0 1 0 7 1 # a comment\n4 0 0 1 7 1\n5 1 1 1 7 1\n");
  char npath[256];
  snprintf(npath, sizeof npath, "%s", node);
  test_write_tmp("vol_tg.ele", "2 4 1\n1 1 2 3 4 9\n2 2 4 3 5 9\n");
  CHECK(volume_import(npath, &t, &r, &err) == 0);
  CHECK(t.nnodes == 5 && t.ntets == 2 && r.flipped == 1);
  tet_mesh_free(&t);
  unlink(npath);
  unlink(test_tmp_path("vol_tg.ele"));
}

static void refusals(void) {
  refused("vol_r1.msh",
          "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"
          "$EndNodes\n$Elements\n1\n1 4 0 1 2 3 99\n$EndElements\n",
          13, "node 99");
  refused("vol_r2.msh",
          "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n$EndNodes\n"
          "$Elements\n1\n1 5 0 1 1 1 1 1 1 1 1\n$EndElements\n",
          10, "hexahedron");
  refused("vol_r3.msh", "$MeshFormat\n4.1 1 8\n", 2, "binary");
  /* control bytes (here an escape sequence) are named, never echoed */
  refused("vol_r3b.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$No\033[2Jdes\n", 4, "a control byte 0x1b");
  refused("vol_r3c.vtk",
          "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 double\n0 0 \0010\n", 6,
          "a control byte 0x01");
  refused("vol_r4.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n2\n1 0 0 0\n2 0 zero 0\n", 7, "not a number");
  refused("vol_r5.msh",
          "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 1 1 0\n"
          "$EndNodes\n$Elements\n1\n1 4 0 1 2 3 4\n$EndElements\n",
          13, "no volume");
  refused("vol_r6.msh",
          "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n6\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"
          "5 0 0 -1\n6 -1 -1 -1\n$EndNodes\n$Elements\n3\n1 4 0 1 2 3 4\n2 4 0 1 2 3 5\n3 4 0 1 2 3 6\n"
          "$EndElements\n",
          15, "shared by 3");
  refused("vol_r7.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n", 7, "ends");
  refused("vol_r8.msh", "$MeshFormat\n3.0 0 8\n", 2, "version");
  refused("vol_r9.msh",
          "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"
          "$EndNodes\n$Elements\n1\n1 4 0 1 2 2 4\n$EndElements\n",
          13, "twice");
  refused("vol_r10.vtk",
          "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 1 double\n0 0 0\n"
          "CELLS 1 9\n8 0 0 0 0 0 0 0 0\nCELL_TYPES 1\n12\n",
          10, "hexahedron");
  refused("vol_r11.vtk",
          "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 2 double\n"
          "0 0 0\n1 nan 0\n",
          7, "finite");
  refused("vol_r12.vtk", "# vtk DataFile Version 3.0\nt\nBINARY\n", 3, "ASCII");
  refused("vol_r13.vtk", "# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\n", 4, "UNSTRUCTURED_GRID");
  refused("vol_r14.node", "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", 0, "cannot open");
  test_write_tmp("vol_r15.ele", "1 10 0\n1 1 2 3 4 5 6 7 8 9 10\n");
  refused("vol_r15.node", "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", 1, "linear");
  unlink(test_tmp_path("vol_r15.ele"));
  refused("vol_r16.msh",
          "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n$EndNodes\n$Elements\n0\n"
          "$EndElements\n",
          0, "no tetrahedra");
  refused("vol_r17.msh", "garbage\n", 1, "$MeshFormat");
  refused("vol_r18.stl", "solid\n", 0, "not a volume mesh");
}

/* The boundary of a filled organ is closed and encloses what its
 * tetrahedra fill; the box grid's boundary is its six sides. */
static void boundary_and_embedding(void) {
  tet_mesh_t box;
  verr_t err = {{0}};
  CHECK(tet_mesh_box_grid(4, 3, 3, 0.01, &box, &err) == 0);
  mesh_t s;
  uint32_t *node_of = NULL;
  CHECK(tet_mesh_boundary(&box, &s, &node_of, NULL, &err) == 0);
  CHECK_NEAR(mesh_signed_volume(&s), 0.03 * 0.02 * 0.02, 1e-15);
  /* Every node but the inside ones (2 x 1 x 1 of 4 x 3 x 3) is on it. */
  CHECK(s.nverts == 36 - 2);
  int on_node = 1;
  for (size_t v = 0; v < s.nverts; v++) on_node &= !memcmp(s.pos + 3 * v, box.x + 3 * (size_t)node_of[v], 24);
  CHECK(on_node);
  free(node_of);

  /* Embedding: the boundary's vertices reproduce exactly, an inside point
   * too, and a point 5 mm beyond the +x side is outside by 5 mm. */
  double pts[3 * 3] = {0.012, 0.007, 0.013, 0.035, 0.01, 0.01, 0, 0, 0};
  memcpy(pts + 6, s.pos + 3 * 5, 24);
  tet_embedding_t e;
  tet_embed_report_t rep;
  CHECK(tet_embed_points(&box, pts, 3, &e, &rep, &err) == 0);
  CHECK(rep.outside == 1);
  CHECK_NEAR(rep.max_distance, 0.005, 1e-12);
  double back[9];
  tet_embedding_apply(&e, &box, box.x, back);
  double worst = 0;
  for (int i = 0; i < 9; i++) worst = fmax(worst, fabs(back[i] - pts[i]));
  CHECK(worst < 1e-15);
  tet_embedding_free(&e);
  mesh_free(&s);
  round_trip(&box, "box");
  tet_mesh_free(&box);

  mesh_t kid;
  if (test_mesh_load("kidney.obj", &kid)) {
    CHECK(0);
    return;
  }
  tet_mesh_t t;
  CHECK(tet_mesh_build(&kid, 0.008, &t, NULL, NULL, &err) == 0);
  double vt = 0;
  for (size_t i = 0; i < t.ntets; i++) vt += tet_volume(&t, t.x, i);
  CHECK(tet_mesh_boundary(&t, &s, NULL, NULL, &err) == 0);
  CHECK_NEAR(mesh_signed_volume(&s), vt, 1e-9 * vt);
  /* The kidney's own surface embeds in its fill, none of it far outside. */
  CHECK(tet_embed_points(&t, kid.pos, kid.nverts, &e, &rep, &err) == 0);
  CHECK(rep.max_distance < 0.004);
  tet_embedding_free(&e);
  mesh_free(&s);
  round_trip(&t, "kidney");
  tet_mesh_free(&t);
  mesh_free(&kid);
}

int main(void) {
  hand_written();
  refusals();
  boundary_and_embedding();
  return check_report("test_volume_mesh");
}
