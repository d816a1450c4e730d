/* SPDX-License-Identifier: Apache-2.0 */
/* organ_geometry: an organ's rest geometry as its scene entry names it,
 * placed in the scene (coordinates * scale + position): the surface mesh
 * (`mesh`, any format assimp reads), and, when the entry names `volume`,
 * the organ's own tetrahedra (common/volume_mesh.h). Without `mesh` the
 * surface is the boundary of the tetrahedra.
 *
 * On success surface owns its arrays (mesh_free) and volume its arrays or
 * is empty (tet_mesh_free); on failure both are empty and err says what is
 * wrong with which file (the caller names the organ). */
#ifndef VISCERA_ORGAN_GEOMETRY_H
#define VISCERA_ORGAN_GEOMETRY_H

#include "mesh.h"
#include "scene.h"
#include "tet_mesh.h"
#include "verr.h"

int organ_geometry_load(const scene_organ_t *cfg, mesh_t *surface, tet_mesh_t *volume, verr_t *err);

#endif
