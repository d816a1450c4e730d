/* SPDX-License-Identifier: Apache-2.0 */
/* tet_mesh: tetrahedral volume meshes, built automatically from an organ's
 * surface, and the barycentric embedding of the render surface in them.
 *
 * tet_mesh_build() fills the inside of a closed (or nearly closed: real
 * meshes have holes and slivers) triangle surface with tetrahedra of about
 * `target_edge` metres (0: chosen from the surface's size, ~8 cells across
 * its smallest extent, at least 1,000 tetrahedra), positively oriented, and
 * embeds every surface vertex in one tetrahedron (barycentric weights; a
 * vertex outside every tetrahedron uses its nearest one, weights then
 * extrapolate, never NaN). The result is plain arrays, allocated once.
 * tet_mesh_box_grid() builds a regular bar for benchmarks and tests. */
#ifndef VISCERA_TET_MESH_H
#define VISCERA_TET_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "mesh.h"
#include "verr.h"

typedef struct tet_mesh {
  size_t nnodes, ntets;
  double *x;      /* 3 nnodes, rest positions */
  uint32_t *tets; /* 4 ntets, positive orientation: det[x1-x0, x2-x0, x3-x0] > 0 */
} tet_mesh_t;

typedef struct tet_embedding {
  size_t nsurf;
  uint32_t *tet; /* nsurf: the tetrahedron holding each surface vertex */
  double *bary;  /* 4 nsurf */
} tet_embedding_t;

typedef struct tet_build_report {
  double seconds;        /* wall time of the build */
  size_t nodes, tets;
  double min_quality;    /* radius ratio 3 r_in / r_circ, 1 = regular, 0 = flat */
  double mean_quality;
  double volume;         /* m^3, tetrahedra */
  double surface_volume; /* m^3, enclosed by the surface (signed) */
  size_t outside_vertices; /* surface vertices embedded by nearest tetrahedron */
} tet_build_report_t;

int tet_mesh_build(const mesh_t *surface, double target_edge, tet_mesh_t *out, tet_embedding_t *emb,
                   tet_build_report_t *report, verr_t *err);
/* nx * ny * nz nodes on a grid of spacing h starting at the origin, each cell
 * split into 5 tetrahedra with alternating orientation so faces match:
 * 30 x 5 x 5 nodes give 750 nodes and 2,320 tetrahedra (the BarDemo bar). */
int tet_mesh_box_grid(size_t nx, size_t ny, size_t nz, double h, tet_mesh_t *out, verr_t *err);
void tet_mesh_free(tet_mesh_t *t);
void tet_embedding_free(tet_embedding_t *e);

/* surf_x[3 nsurf] = sum_k bary_k x_nodes[tet_k]. */
void tet_embedding_apply(const tet_embedding_t *e, const tet_mesh_t *t, const double *x_nodes, double *surf_x);
/* Signed volume of tetrahedron i at positions x (3 nnodes). */
double tet_volume(const tet_mesh_t *t, const double *x, size_t i);
/* Radius-ratio quality of tetrahedron i at positions x, in [0, 1]. */
double tet_quality(const tet_mesh_t *t, const double *x, size_t i);

#endif
