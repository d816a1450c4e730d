/* SPDX-License-Identifier: Apache-2.0 */
/* tet_model_cut: cutting a tetrahedral model (model.h edit kind
 * MODEL_EDIT_TETS: pbd, xpbd) with a scalpel: the progressive cutter of
 * tet_cut.h on its own copy of the model's mesh, committed to the model
 * (model.h edit->commit) whenever tetrahedra split.
 *
 * Ownership: the caller owns the cutter (the runtime's cut phase keeps one
 * per pbd/xpbd organ, runtime/step_cut.c) and destroys it before the model;
 * the model knows nothing of it. tet_model_cut_create allocates only this
 * object: the mesh is copied by tet_model_cut_prepare (a scene with a
 * scalpel, at load) or by the first advance, so a model nobody cuts holds
 * nothing for cutting (tet_model_cut_mesh stays NULL).
 *
 * One call per scene step with the blade segment (tip, handle; metres, in
 * the model's coordinates: the scene frame), between model steps, one to
 * end the cut. Each call first takes the model's current positions and
 * velocities (the cutter's nodes are the model's, committed together);
 * when tetrahedra split, the new mesh (nodes, tetrahedra, boundary with
 * the incision faces, per-node attributes) is committed and the model's
 * topology_version moves. Both return the number of tetrahedra split
 * (>= 0) or -1 with err (bad blade, out of memory: the model keeps
 * simulating its last topology). A commit that failed leaves the cutter
 * ahead of the model: cutting is then refused for good.
 *
 * Checkpoints: the model's cut topology is this cutter's mesh, so the
 * cutter saves it (tet_model_cut_save: tet_cut_save and the model's
 * topology_version) and restores it into a fresh model built from the same
 * scene (tet_model_cut_restore: the mesh and the cutter's memory of
 * earlier cuts, then the node positions x and velocities v, 3 nnodes each;
 * untrusted bytes, checked; the model changes only when all succeeded).
 * Not thread-safe: the physics thread, between steps. */
#ifndef VISCERA_TET_MODEL_CUT_H
#define VISCERA_TET_MODEL_CUT_H

#include <stddef.h>

#include "cutting/tet_cut.h"
#include "physics/model.h"
#include "verr.h"

typedef struct tet_model_cut tet_model_cut_t;

/* NULL with err for a model that is not a MODEL_EDIT_TETS model. */
tet_model_cut_t *tet_model_cut_create(model_t *m, verr_t *err);
void tet_model_cut_destroy(tet_model_cut_t *c);
/* Copies the model's mesh now (no-op when done). 0, or -1 with err. */
int tet_model_cut_prepare(tet_model_cut_t *c, verr_t *err);
int tet_model_cut_advance(tet_model_cut_t *c, const double tip[3], const double handle[3], verr_t *err);
int tet_model_cut_end(tet_model_cut_t *c, verr_t *err);
/* The cutter's mesh and statistics; NULL before prepare or the first cut. */
const tet_cut_t *tet_model_cut_mesh(const tet_model_cut_t *c);

struct state_blob;
/* 0, or -1 when there is nothing to save (no mesh, a failed commit) or out of memory. */
int tet_model_cut_save(const tet_model_cut_t *c, struct state_blob *b);
int tet_model_cut_restore(tet_model_cut_t *c, struct state_blob *b, size_t nnodes, const double *x, const double *v,
                          verr_t *err);

#endif
