/* SPDX-License-Identifier: Apache-2.0 */
/* mesh: an indexed triangle surface, the form every part of viscera shares.
 * Positions are double (metres), 3 per vertex; triangles are 3 uint32 indices,
 * counter-clockwise seen from outside (outward normals). A mesh owns its arrays. */
#ifndef VISCERA_MESH_H
#define VISCERA_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "verr.h"

typedef struct mesh {
  size_t nverts;
  size_t ntris;
  double *pos;    /* 3 * nverts */
  uint32_t *tris; /* 3 * ntris */
} mesh_t;

/* Allocates zeroed arrays; returns 0, or -1 with err set on overflow / OOM. */
int mesh_alloc(mesh_t *m, size_t nverts, size_t ntris, verr_t *err);
void mesh_free(mesh_t *m);
/* Deep copy into dst (dst is overwritten, not freed first). */
int mesh_copy(mesh_t *dst, const mesh_t *src, verr_t *err);

void mesh_bounds(const mesh_t *m, double bmin[3], double bmax[3]);
/* Area-weighted vertex normals (unit length, or zero for isolated vertices)
 * into out[3 * nverts]. Works on any float/double position array via pos. */
void mesh_vertex_normals_f(size_t nverts, const float *pos, size_t ntris, const uint32_t *tris, float *out);
/* Signed volume (positive for outward-oriented closed meshes). */
double mesh_signed_volume(const mesh_t *m);
/* Checks every index < nverts and every coordinate finite; names the first
 * offender in err. `what` names the source (a file name) for the message. */
int mesh_validate(const mesh_t *m, const char *what, verr_t *err);

/* Wavefront OBJ writer ("v" and "f" lines only): the form the server and the
 * asset tool exchange. */
int mesh_write_obj(const mesh_t *m, const char *path, const char *comment, verr_t *err);

#endif
