/* SPDX-License-Identifier: Apache-2.0 */
/* model_volume: the tetrahedral mesh a volumetric model (mass_spring_tet,
 * pbd, xpbd) simulates and the embedding of its render surface in it:
 * either the organ's own tetrahedra from a file (model_params_t.volume,
 * common/volume_mesh.h) or the automatic fill of the surface
 * (tet_mesh_build, solver.tet_size).
 *
 * On success tm and emb own their arrays (tet_mesh_free,
 * tet_embedding_free) and emb holds every surface vertex; on failure both
 * are empty and err says why, without naming the organ (model_create does). */
#ifndef VISCERA_MODEL_VOLUME_H
#define VISCERA_MODEL_VOLUME_H

#include "physics/model.h"
#include "tet_mesh.h"

/* A surface vertex farther than this fraction of the volume's largest
 * extent outside every tetrahedron means the two files do not belong
 * together (a different scale, position or organ). */
#define MODEL_VOLUME_MAX_OUTSIDE 0.05

int model_volume_obtain(const model_params_t *p, tet_mesh_t *tm, tet_embedding_t *emb, verr_t *err);

#endif
