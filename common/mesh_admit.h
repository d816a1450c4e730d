/* SPDX-License-Identifier: Apache-2.0 */
/* mesh_admit: what an organ mesh must be before a model is built on it,
 * refused or repaired with a message (issue 15: meshes 1e30 m or 1e-30 m
 * across, inside out, inconsistently wound, non-manifold, open or in two
 * parts were taken without a word).
 *
 * Refused (-1, err names `what` and the defect with its count and a first
 * example): an empty mesh, a non-finite coordinate, an index out of range
 * (mesh_validate); a size (bounding-box diagonal) outside
 * [min_size, max_size]; degenerate triangles (zero area or a repeated
 * index, mesh_check.h); non-manifold edges (more than two triangles); more
 * than one connected part; boundary edges unless allow_open; a surface
 * that cannot be oriented (Moebius-like), or a closed one with no volume.
 * Repaired (0, each repair described in `note`): triangles wound against
 * their neighbours are re-wound to agree with the first triangle; a closed
 * surface whose volume comes out negative (inside out) is turned outward.
 * A clean mesh returns 0 with note "". O(V + T log T) time, allocates
 * temporaries only; thread-safe on distinct meshes. */
#ifndef VISCERA_MESH_ADMIT_H
#define VISCERA_MESH_ADMIT_H

#include <stddef.h>

#include "mesh.h"
#include "verr.h"

typedef struct mesh_admit_opts {
  int allow_open;  /* 1: a surface with boundary edges (a tissue sheet) is taken */
  double min_size; /* m, smallest bounding-box diagonal */
  double max_size; /* m, largest */
} mesh_admit_opts_t;

/* 0.1 mm (below it the 1e-5 m quantization and contact tolerances are the
 * organ) to 10 m (no organ; a file in millimetres without scale: 0.001). */
#define MESH_ADMIT_MIN_SIZE 1e-4
#define MESH_ADMIT_MAX_SIZE 10.0

int mesh_admit(mesh_t *m, const mesh_admit_opts_t *o, const char *what, char *note, size_t note_size, verr_t *err);

#endif
