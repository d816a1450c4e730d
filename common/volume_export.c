/* SPDX-License-Identifier: Apache-2.0 */
/* Writers of the formats volume_import() reads (volume_mesh.h), used by the
 * asset tool to hand a generated tetrahedral mesh to other tools and by the
 * tests to make small files in every format. Coordinates with 17
 * significant digits, so a round trip is exact. */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "volume_mesh.h"

int volume_format_parse(const char *name) {
  static const char *const names[] = {
      [VOLUME_MSH2] = "msh2", [VOLUME_MSH4] = "msh4", [VOLUME_VTK] = "vtk", [VOLUME_TETGEN] = "tetgen"};
  for (int i = 0; i < 4; i++)
    if (!strcmp(name, names[i])) return i;
  return -1;
}

static void write_msh2(FILE *f, const tet_mesh_t *t) {
  fprintf(f, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%zu\n", t->nnodes);
  for (size_t i = 0; i < t->nnodes; i++)
    fprintf(f, "%zu %.17g %.17g %.17g\n", i + 1, t->x[3 * i], t->x[3 * i + 1], t->x[3 * i + 2]);
  fprintf(f, "$EndNodes\n$Elements\n%zu\n", t->ntets);
  for (size_t i = 0; i < t->ntets; i++) {
    const uint32_t *c = t->tets + 4 * i;
    fprintf(f, "%zu 4 2 1 1 %u %u %u %u\n", i + 1, c[0] + 1, c[1] + 1, c[2] + 1, c[3] + 1);
  }
  fprintf(f, "$EndElements\n");
}

static void write_msh4(FILE *f, const tet_mesh_t *t) {
  fprintf(f, "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
  fprintf(f, "$Nodes\n1 %zu 1 %zu\n3 1 0 %zu\n", t->nnodes, t->nnodes, t->nnodes);
  for (size_t i = 0; i < t->nnodes; i++) fprintf(f, "%zu\n", i + 1);
  for (size_t i = 0; i < t->nnodes; i++)
    fprintf(f, "%.17g %.17g %.17g\n", t->x[3 * i], t->x[3 * i + 1], t->x[3 * i + 2]);
  fprintf(f, "$EndNodes\n$Elements\n1 %zu 1 %zu\n3 1 4 %zu\n", t->ntets, t->ntets, t->ntets);
  for (size_t i = 0; i < t->ntets; i++) {
    const uint32_t *c = t->tets + 4 * i;
    fprintf(f, "%zu %u %u %u %u\n", i + 1, c[0] + 1, c[1] + 1, c[2] + 1, c[3] + 1);
  }
  fprintf(f, "$EndElements\n");
}

static void write_vtk(FILE *f, const tet_mesh_t *t) {
  fprintf(f, "# vtk DataFile Version 3.0\nviscera tetrahedral mesh\nASCII\nDATASET UNSTRUCTURED_GRID\n");
  fprintf(f, "POINTS %zu double\n", t->nnodes);
  for (size_t i = 0; i < t->nnodes; i++)
    fprintf(f, "%.17g %.17g %.17g\n", t->x[3 * i], t->x[3 * i + 1], t->x[3 * i + 2]);
  fprintf(f, "CELLS %zu %zu\n", t->ntets, 5 * t->ntets);
  for (size_t i = 0; i < t->ntets; i++) {
    const uint32_t *c = t->tets + 4 * i;
    fprintf(f, "4 %u %u %u %u\n", c[0], c[1], c[2], c[3]);
  }
  fprintf(f, "CELL_TYPES %zu\n", t->ntets);
  for (size_t i = 0; i < t->ntets; i++) fprintf(f, "10\n");
}

static void write_node(FILE *f, const tet_mesh_t *t) {
  fprintf(f, "# viscera tetrahedral mesh: nodes\n%zu 3 0 0\n", t->nnodes);
  for (size_t i = 0; i < t->nnodes; i++)
    fprintf(f, "%zu %.17g %.17g %.17g\n", i, t->x[3 * i], t->x[3 * i + 1], t->x[3 * i + 2]);
}

static void write_ele(FILE *f, const tet_mesh_t *t) {
  fprintf(f, "# viscera tetrahedral mesh: tetrahedra\n%zu 4 0\n", t->ntets);
  for (size_t i = 0; i < t->ntets; i++) {
    const uint32_t *c = t->tets + 4 * i;
    fprintf(f, "%zu %u %u %u %u\n", i, c[0], c[1], c[2], c[3]);
  }
}

static int write_file(const char *path, const tet_mesh_t *t, void (*w)(FILE *, const tet_mesh_t *), verr_t *err) {
  FILE *f = fopen(path, "w");
  if (!f) return verr_set(err, "%s: cannot create: %s", path, strerror(errno));
  w(f, t);
  int bad = ferror(f);
  if (fclose(f) || bad) return verr_set(err, "%s: write failed: %s", path, strerror(errno));
  return 0;
}

int volume_export(const tet_mesh_t *t, volume_format_t fmt, const char *path, verr_t *err) {
  switch (fmt) {
  case VOLUME_MSH2:
    return write_file(path, t, write_msh2, err);
  case VOLUME_MSH4:
    return write_file(path, t, write_msh4, err);
  case VOLUME_VTK:
    return write_file(path, t, write_vtk, err);
  case VOLUME_TETGEN: {
    char stem[4096], p[4200];
    size_t n = strlen(path);
    if (n >= 5 && !strcmp(path + n - 5, ".node")) n -= 5;
    if (n >= sizeof stem) return verr_set(err, "%s: path too long", path);
    snprintf(stem, sizeof stem, "%.*s", (int)n, path);
    snprintf(p, sizeof p, "%s.node", stem);
    if (write_file(p, t, write_node, err)) return -1;
    snprintf(p, sizeof p, "%s.ele", stem);
    return write_file(p, t, write_ele, err);
  }
  }
  return verr_set(err, "unknown volume format %d", (int)fmt);
}
