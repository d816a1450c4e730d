/* SPDX-License-Identifier: Apache-2.0 */
/* mesh_check: what is wrong with a triangle mesh, measured, never repaired.
 * Works on any mesh_t, including broken ones: faces with an out-of-range index
 * and non-finite vertices are counted and left out of the other measures.
 * Cost O(V log V + T); no global state, so thread-safe on distinct reports. */
#ifndef VISCERA_MESH_CHECK_H
#define VISCERA_MESH_CHECK_H

#include <stddef.h>
#include <stdio.h>

#include "mesh.h"

/* A face is degenerate when its height is below this fraction of its longest
 * edge (zero area, whatever the mesh's scale), or it repeats an index. */
#define MESH_CHECK_DEGENERATE_REL 1e-6

typedef struct mesh_report {
  size_t vertices, triangles;
  double bmin[3], bmax[3], size[3]; /* over all finite vertices, in file units */
  size_t edges;                     /* distinct undirected edges */
  size_t boundary_edges;            /* used by one face */
  size_t nonmanifold_edges;         /* used by more than two faces */
  int closed;                       /* no boundary and no non-manifold edge */
  size_t inconsistent_edges;        /* two faces crossing it in the same direction */
  size_t degenerate_faces;
  double min_angle_deg;         /* smallest corner angle of the other faces: mesh quality */
  size_t duplicate_vertices;    /* same position as an earlier vertex: not welded */
  size_t unreferenced_vertices; /* in no face */
  size_t components;            /* face sets connected through shared vertices */
  double volume;                /* signed, outward positive; meaningful only when closed */
  long long euler;              /* V - E + F, V counting referenced vertices only */
  size_t bad_index_faces;       /* faces naming a vertex >= vertices */
  size_t nonfinite_vertices;
} mesh_report_t;

/* Fills r; returns 0, or -1 when memory runs out (r then zeroed). */
int mesh_check(const mesh_t *m, mesh_report_t *r);
/* Number of kinds of problem the report shows (0: a clean closed surface). An
 * open surface counts as a problem; callers that want a patch check boundary_edges. */
int mesh_report_problems(const mesh_report_t *r);
/* Human-readable: the measures, then "problems found:" with one line per kind,
 * or "no problems found". */
void mesh_report_print(const mesh_report_t *r, FILE *f);

#endif
