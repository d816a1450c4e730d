/* SPDX-License-Identifier: Apache-2.0 */
/* volume_mesh: tetrahedral meshes made offline (gmsh, TetGen, any tool that
 * writes VTK), read into a tet_mesh_t the tetrahedral models simulate, and
 * written back in the same formats (the asset tool's `tet --out`).
 *
 * Formats, chosen by the file name:
 *   .msh        gmsh MSH 2.2 and 4.0/4.1, ASCII. 4-node tetrahedra (type 4)
 *               are read; points, lines and triangles (types 15, 1, 2) are
 *               skipped; any other element (hexahedra, prisms, 10-node
 *               tetrahedra, ...) is refused, as is the binary form.
 *   .vtk        VTK legacy ASCII, DATASET UNSTRUCTURED_GRID, CELLS in the
 *               classic (count + indices per cell) or the 5.1 OFFSETS /
 *               CONNECTIVITY layout. Tetrahedra (cell type 10) are read;
 *               vertices, lines, triangles (1, 3, 5) skipped; others refused.
 *   .node/.ele  TetGen: the two files side by side, either name given.
 *               4 corners per tetrahedron (10 refused); indices from 0 or 1.
 *
 * What is refused, with "file:line: what": a file that does not parse, a
 * coordinate that is not finite, a corner naming no node, a tetrahedron
 * with a repeated corner or (nearly) no volume, a face shared by more than
 * two tetrahedra, no tetrahedra at all, more than VOLUME_MAX_TETS. What is
 * repaired, and counted in the report: tetrahedra with negative orientation
 * (two corners swapped) and nodes no tetrahedron uses (dropped).
 *
 * Ownership: on success *out owns its arrays (tet_mesh_free); on failure
 * *out is empty. Single-threaded, no global state. */
#ifndef VISCERA_VOLUME_MESH_H
#define VISCERA_VOLUME_MESH_H

#include <stddef.h>

#include "tet_mesh.h"
#include "verr.h"

#define VOLUME_MAX_TETS 200000

typedef struct volume_report {
  size_t nodes, tets;
  size_t flipped; /* tetrahedra whose orientation was reversed */
  size_t unused;  /* nodes dropped because no tetrahedron uses them */
  size_t skipped; /* lower-dimensional elements skipped (points, lines, triangles) */
  double volume;  /* m^3 (file units cubed), after repair */
  double min_quality;
} volume_report_t;

typedef enum { VOLUME_MSH2, VOLUME_MSH4, VOLUME_VTK, VOLUME_TETGEN } volume_format_t;

/* Reads path (format from its name, see above). report may be NULL. */
int volume_import(const char *path, tet_mesh_t *out, volume_report_t *report, verr_t *err);
/* 1 when path names a volume format this module reads (.msh .vtk .node .ele). */
int volume_path_known(const char *path);

/* Writes t to path in format f. For VOLUME_TETGEN, path names the .node
 * file (or its stem) and the .ele file is written beside it. */
int volume_export(const tet_mesh_t *t, volume_format_t f, const char *path, verr_t *err);
/* "msh2" "msh4" "vtk" "tetgen" -> format; -1 when unknown. */
int volume_format_parse(const char *name);

#endif
