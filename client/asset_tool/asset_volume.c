/* SPDX-License-Identifier: Apache-2.0 */
#include "asset_volume.h"

#include <stdio.h>
#include <string.h>

#include "mesh.h"
#include "tet_embed.h"

static int ends_with(const char *s, const char *suffix) {
  size_t a = strlen(s), b = strlen(suffix);
  return a >= b && !strcmp(s + a - b, suffix);
}

int asset_volume_format(const char *out, const char *name) {
  if (name) {
    int f = volume_format_parse(name);
    if (f < 0) bad_usage("tet: --format must be msh2, msh4, vtk or tetgen, not '%s'", name);
    return f;
  }
  if (ends_with(out, ".msh")) return VOLUME_MSH4;
  if (ends_with(out, ".vtk")) return VOLUME_VTK;
  if (ends_with(out, ".node")) return VOLUME_TETGEN;
  bad_usage("tet: cannot tell the format of '%s' (use .msh, .vtk or .node, or --format)", out);
  return -1;
}

int asset_volume_info(int argc, char **argv) {
  if (argc != 1 || argv[0][0] == '-') return bad_usage("volume: give exactly one FILE");
  const char *in = argv[0];
  tet_mesh_t t;
  volume_report_t r;
  verr_t err = {{0}};
  if (volume_import(in, &t, &r, &err)) {
    fprintf(stderr, "viscera-asset: %s\n", err.msg);
    return EXIT_ERROR;
  }
  mesh_t surf;
  int rc = tet_mesh_boundary(&t, &surf, NULL, NULL, &err);
  printf("%s: tetrahedral mesh\n", in);
  printf("  nodes           %zu\n", r.nodes);
  printf("  tetrahedra      %zu\n", r.tets);
  printf("  volume          %.6g\n", r.volume);
  printf("  quality         min %.3f (radius ratio, 1 = regular)\n", r.min_quality);
  printf("  repaired        %zu tetrahedra turned to positive orientation, %zu unused nodes dropped\n", r.flipped,
         r.unused);
  printf("  skipped         %zu lower-dimensional elements (points, lines, triangles)\n", r.skipped);
  if (!rc) {
    printf("  boundary        %zu vertices, %zu triangles, encloses %.6g\n", surf.nverts, surf.ntris,
           mesh_signed_volume(&surf));
    mesh_free(&surf);
  } else {
    fprintf(stderr, "viscera-asset: %s: boundary: %s\n", in, err.msg);
  }
  tet_mesh_free(&t);
  return rc ? EXIT_ERROR : EXIT_OK;
}
