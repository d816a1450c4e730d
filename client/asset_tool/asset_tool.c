/* SPDX-License-Identifier: Apache-2.0 */
/* viscera-asset: inspects mesh files and converts them to the OBJ form the
 * server loads (through the same mesh_import, so what this tool reports is
 * what the server sees). See usage() for the commands. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "cli.h"
#include "mesh.h"
#include "mesh_check.h"
#include "mesh_import.h"
#include "tet_mesh.h"

#include "asset_usage.h"
#include "asset_volume.h"


static void usage(FILE *f) {
  fprintf(f, "usage: viscera-asset info [--strict] FILE...\n"
             "       viscera-asset convert IN OUT.obj [--scale S] [--center] [--strict]\n"
             "       viscera-asset tet FILE [--size S] [--out OUT [--format F]]\n"
             "       viscera-asset volume FILE\n"
             "       viscera-asset --help | --version\n"
             "\n"
             "info     imports each FILE (any format assimp reads: OBJ, STL, PLY, glTF, ...),\n"
             "         welds it as the server would and prints its check report: size,\n"
             "         closedness, non-manifold and inconsistently oriented edges, degenerate\n"
             "         faces, components, volume and a list of problems.\n"
             "convert  imports IN, applies the options, prints the report and writes the\n"
             "         welded mesh to OUT.obj (v and f lines only), the form assets/ keeps.\n"
             "tet      imports FILE, fills its inside with tetrahedra as the simulator does and\n"
             "         prints the result: nodes, tetrahedra, build time, minimum and mean\n"
             "         quality (radius ratio, 1 = regular), tetrahedra volume over the volume\n"
             "         the surface encloses, and surface vertices outside every tetrahedron\n"
             "         (embedded by their nearest one). Fails on a surface enclosing nothing\n"
             "         (an open patch) and on more than 200,000 tetrahedra. With --out, writes\n"
             "         the tetrahedra to OUT for other tools or a scene's `volume:` key.\n"
             "volume   reads a tetrahedral mesh (gmsh .msh 2/4 ASCII, VTK legacy .vtk, TetGen\n"
             "         .node/.ele) as the server does for an organ's `volume:` and prints what\n"
             "         it holds and what was repaired (flipped tetrahedra, unused nodes), or\n"
             "         the line it refuses.\n"
             "\n"
             "options:\n"
             "  --scale S   multiply every coordinate by S (> 0), e.g. 0.01 for a file in\n"
             "              centimetres, since viscera works in metres\n"
             "  --center    move the mesh so its bounding box is centred in x and y and its\n"
             "              lowest point is at z = 0 (the convention of assets/meshes)\n"
             "  --strict    treat any problem in the report as failure; convert then writes\n"
             "              nothing\n"
             "  --size S    tet: edge of the grid cells in the file's units (> 0); default:\n"
             "              automatic, about 8 cells across the smallest extent and at least\n"
             "              1,000 tetrahedra\n"
             "  --out OUT   tet: write the tetrahedra to OUT (.msh, .vtk or .node)\n"
             "  --format F  tet: msh2, msh4, vtk or tetgen (default: from OUT's name; .msh\n"
             "              is written as msh4)\n"
             "\n"
             "exit status: 0 success, 1 a file could not be read or written, (tet) could not\n"
             "be filled or (volume) was refused, 2 bad usage, 3 --strict and a problem was\n"
             "found.\n");
}


/* viscera works in metres; an organ a metre long almost surely is not. */
static void units_hint(const mesh_report_t *r) {
  double ext = fmax(r->size[0], fmax(r->size[1], r->size[2]));
  if (ext > 1.0)
    printf("  note: largest extent %g: if these units are not metres, convert with --scale\n"
           "        (0.01 for centimetres, 0.001 for millimetres)\n",
           ext);
}

/* Imports and reports one file; returns an exit status. */
static int info_one(const char *path, int strict) {
  mesh_t m;
  mesh_report_t r;
  verr_t err = {{0}};
  if (mesh_import(path, &m, &err)) {
    fprintf(stderr, "viscera-asset: %s\n", err.msg);
    return EXIT_ERROR;
  }
  int rc = mesh_check(&m, &r);
  mesh_free(&m);
  if (rc) {
    fprintf(stderr, "viscera-asset: %s: out of memory checking the mesh\n", path);
    return EXIT_ERROR;
  }
  printf("%s:\n", path);
  mesh_report_print(&r, stdout);
  units_hint(&r);
  return strict && mesh_report_problems(&r) ? EXIT_PROBLEMS : EXIT_OK;
}

static int cmd_info(int argc, char **argv) {
  int strict = 0, files = 0, worst = EXIT_OK;
  for (int i = 0; i < argc; i++) {
    if (!strcmp(argv[i], "--strict"))
      strict = 1;
    else if (argv[i][0] == '-' && argv[i][1])
      return bad_usage("info: unknown option '%s'", argv[i]);
  }
  for (int i = 0; i < argc; i++) {
    if (!strcmp(argv[i], "--strict")) continue;
    int rc = info_one(argv[i], strict);
    /* A read error outranks a problem report; both outrank success. */
    if (rc == EXIT_ERROR || (rc == EXIT_PROBLEMS && worst == EXIT_OK)) worst = rc;
    files++;
  }
  if (!files) return bad_usage("info: no FILE given");
  return worst;
}

static int ends_with_obj(const char *s) {
  size_t n = strlen(s);
  return n > 4 && !strcasecmp(s + n - 4, ".obj");
}

static void transform(mesh_t *m, double scale, int center) {
  for (size_t i = 0; i < 3 * m->nverts; i++) m->pos[i] *= scale;
  if (!center) return;
  double lo[3], hi[3];
  mesh_bounds(m, lo, hi);
  double shift[3] = {-0.5 * (lo[0] + hi[0]), -0.5 * (lo[1] + hi[1]), -lo[2]};
  for (size_t v = 0; v < m->nverts; v++)
    for (int k = 0; k < 3; k++) m->pos[3 * v + k] += shift[k];
}

static int cmd_convert(int argc, char **argv) {
  const char *in = NULL, *out = NULL;
  double scale = 1;
  int center = 0, strict = 0;
  for (int i = 0; i < argc; i++) {
    const char *a = argv[i];
    if (!strcmp(a, "--scale") || !strncmp(a, "--scale=", 8)) {
      const char *v = a[7] == '=' ? a + 8 : (i + 1 < argc ? argv[++i] : NULL);
      if (!v) return bad_usage("convert: --scale needs a value");
      char *end;
      scale = strtod(v, &end);
      if (end == v || *end || !isfinite(scale) || scale <= 0)
        return bad_usage("convert: --scale must be a positive number, not '%s'", v);
    } else if (!strcmp(a, "--center") || !strcmp(a, "--centre")) {
      center = 1;
    } else if (!strcmp(a, "--strict")) {
      strict = 1;
    } else if (a[0] == '-' && a[1]) {
      return bad_usage("convert: unknown option '%s'", a);
    } else if (!in) {
      in = a;
    } else if (!out) {
      out = a;
    } else {
      return bad_usage("convert: unexpected argument '%s'", a);
    }
  }
  if (!in || !out) return bad_usage("convert: needs IN and OUT.obj");
  if (!ends_with_obj(out)) return bad_usage("convert: OUT must be an .obj file, not '%s'", out);

  mesh_t m;
  mesh_report_t r;
  verr_t err = {{0}};
  if (mesh_import(in, &m, &err)) {
    fprintf(stderr, "viscera-asset: %s\n", err.msg);
    return EXIT_ERROR;
  }
  transform(&m, scale, center);
  if (mesh_validate(&m, in, &err)) {
    fprintf(stderr, "viscera-asset: after --scale %g: %s\n", scale, err.msg);
    mesh_free(&m);
    return EXIT_ERROR;
  }
  if (mesh_check(&m, &r)) {
    fprintf(stderr, "viscera-asset: %s: out of memory checking the mesh\n", in);
    mesh_free(&m);
    return EXIT_ERROR;
  }
  printf("%s -> %s (scale %g%s):\n", in, out, scale, center ? ", centred" : "");
  mesh_report_print(&r, stdout);
  units_hint(&r);
  if (strict && mesh_report_problems(&r)) {
    fprintf(stderr, "viscera-asset: %s: problems found, %s not written (--strict)\n", in, out);
    mesh_free(&m);
    return EXIT_PROBLEMS;
  }
  char comment[VERR_MSG_LEN];
  snprintf(comment, sizeof comment, "converted by viscera-asset from %s (scale %g%s)", in, scale,
           center ? ", centred" : "");
  int rc = mesh_write_obj(&m, out, comment, &err);
  mesh_free(&m);
  if (rc) {
    fprintf(stderr, "viscera-asset: %s\n", err.msg);
    return EXIT_ERROR;
  }
  return EXIT_OK;
}

static int cmd_tet(int argc, char **argv) {
  const char *in = NULL, *out = NULL, *format = NULL;
  double size = 0;
  for (int i = 0; i < argc; i++) {
    const char *a = argv[i];
    if (!strcmp(a, "--size") || !strncmp(a, "--size=", 7)) {
      const char *v = a[6] == '=' ? a + 7 : (i + 1 < argc ? argv[++i] : NULL);
      if (!v) return bad_usage("tet: --size needs a value");
      char *end;
      size = strtod(v, &end);
      if (end == v || *end || !isfinite(size) || size <= 0)
        return bad_usage("tet: --size must be a positive number, not '%s'", v);
    } else if (!strcmp(a, "--out") || !strcmp(a, "--format")) {
      if (i + 1 >= argc) return bad_usage("tet: %s needs a value", a);
      *(a[2] == 'o' ? &out : &format) = argv[++i];
    } else if (a[0] == '-' && a[1]) {
      return bad_usage("tet: unknown option '%s'", a);
    } else if (!in) {
      in = a;
    } else {
      return bad_usage("tet: unexpected argument '%s'", a);
    }
  }
  if (!in) return bad_usage("tet: no FILE given");
  if (format && !out) return bad_usage("tet: --format needs --out");
  int fmt = -1;
  if (out && (fmt = asset_volume_format(out, format)) < 0) return EXIT_USAGE;

  mesh_t m;
  verr_t err = {{0}};
  if (mesh_import(in, &m, &err)) {
    fprintf(stderr, "viscera-asset: %s\n", err.msg);
    return EXIT_ERROR;
  }
  tet_mesh_t t;
  tet_embedding_t e;
  tet_build_report_t r;
  int rc = tet_mesh_build(&m, size, &t, &e, &r, &err);
  size_t nverts = m.nverts;
  mesh_free(&m);
  if (rc) {
    fprintf(stderr, "viscera-asset: %s: %s\n", in, err.msg);
    return EXIT_ERROR;
  }
  printf("%s: tetrahedral mesh%s\n", in, size > 0 ? "" : " (automatic size)");
  if (size > 0) printf("  cell size       %g\n", size);
  printf("  nodes           %zu\n", r.nodes);
  printf("  tetrahedra      %zu\n", r.tets);
  printf("  build time      %.3f s\n", r.seconds);
  printf("  quality         min %.3f, mean %.3f (radius ratio, 1 = regular)\n", r.min_quality, r.mean_quality);
  printf("  volume          %.6g (surface encloses %.6g): ratio %.4f\n", r.volume, r.surface_volume,
         r.surface_volume != 0 ? r.volume / fabs(r.surface_volume) : NAN);
  printf("  outside         %zu of %zu surface vertices embedded by their nearest tetrahedron\n", r.outside_vertices,
         nverts);
  if (out && volume_export(&t, (volume_format_t)fmt, out, &err)) {
    fprintf(stderr, "viscera-asset: %s\n", err.msg);
    rc = EXIT_ERROR;
  } else if (out) {
    printf("  written         %s\n", out);
  }
  tet_mesh_free(&t);
  tet_embedding_free(&e);
  return rc;
}

int main(int argc, char **argv) {
  if (argc < 2) {
    usage(stderr);
    return EXIT_USAGE;
  }
  const char *cmd = argv[1];
  for (int i = 1; i < argc; i++)
    if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
      usage(stdout);
      return EXIT_OK;
    }
  if (!strcmp(cmd, "help")) {
    usage(stdout);
    return EXIT_OK;
  }
  if (!strcmp(cmd, "--version")) {
    printf("viscera-asset %s\n", cli_version());
    return EXIT_OK;
  }
  if (!strcmp(cmd, "info")) return cmd_info(argc - 2, argv + 2);
  if (!strcmp(cmd, "convert")) return cmd_convert(argc - 2, argv + 2);
  if (!strcmp(cmd, "tet")) return cmd_tet(argc - 2, argv + 2);
  if (!strcmp(cmd, "volume")) return asset_volume_info(argc - 2, argv + 2);
  return bad_usage("unknown command '%s'", cmd);
}
