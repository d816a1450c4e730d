/* SPDX-License-Identifier: Apache-2.0 */
/* tet_embed: the parts of a given tetrahedral mesh the tetrahedral models
 * need when the mesh comes from a file (volume_mesh.h) instead of
 * tet_mesh_build(): a copy, its boundary surface, and the barycentric
 * embedding of a render surface in it.
 *
 * Contracts: positions in metres; t's tetrahedra positively oriented (as
 * volume_import() and tet_mesh_build() leave them). Outputs own their arrays
 * (tet_mesh_free, mesh_free, tet_embedding_free) and are empty on failure.
 * Single-threaded, no global state. */
#ifndef VISCERA_TET_EMBED_H
#define VISCERA_TET_EMBED_H

#include <stddef.h>

#include "mesh.h"
#include "tet_mesh.h"
#include "verr.h"

int tet_mesh_copy(tet_mesh_t *dst, const tet_mesh_t *src, verr_t *err);

/* The faces no two tetrahedra share, outward (counter-clockwise seen from
 * outside), over the nodes they use, compacted in node order. node_of_vert
 * (may be NULL) receives, malloc'd, each surface vertex's node. Refuses a
 * face shared by three or more tetrahedra (*bad_tet, if not NULL, names one
 * of them). */
int tet_mesh_boundary(const tet_mesh_t *t, mesh_t *surf, uint32_t **node_of_vert, size_t *bad_tet, verr_t *err);

typedef struct tet_embed_report {
  size_t outside;      /* points in no tetrahedron: embedded by the nearest one */
  double max_distance; /* m, the farthest of those from its tetrahedron */
} tet_embed_report_t;

/* Embeds n points p[3 n] in t: each in the tetrahedron holding it (the one
 * where it lies deepest when on shared faces), else in the nearest one
 * (weights then extrapolate: affine, never NaN). */
int tet_embed_points(const tet_mesh_t *t, const double *p, size_t n, tet_embedding_t *emb, tet_embed_report_t *rep,
                     verr_t *err);

#endif
