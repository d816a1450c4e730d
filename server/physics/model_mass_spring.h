/* model_mass_spring: what the surface mass-spring model (mass_spring_surface)
 * exposes beyond model_t, for cutting (server/cutting/ms_cut.h), which edits
 * its nodes and triangles.
 *
 * Protocol for a topology change: model_mass_spring_reserve(m, cap) makes
 * room for cap nodes (allocates only when cap exceeds the capacity, then
 * grows it by half again, so a long cut reallocates a few times, never per
 * step); the caller then writes n <= cap nodes into the force system's
 * arrays (x, v, x_rest, mass, inv_mass, f_res) and calls
 * model_mass_spring_commit(), which takes the new triangles, rebuilds the
 * springs, re-chooses the sub-steps from the stability bound (new springs
 * and nodes change it) and increments m->topology_version. old_to_new maps
 * the old_n nodes before the change to their new index (UINT32_MAX: deleted;
 * survivors keep their order); nodes after the survivors are new.
 *
 * The stability bound after the change is available at once, as safe as the
 * one before, without a power iteration (10-20 ms at 5k nodes: a stall):
 * with equal masses K_new = A + B, A the old K less the cut springs and
 * deleted nodes (largest eigenvalue at most the old one), B the springs
 * touching new nodes and their home springs, capped by B's Gershgorin
 * bound; Weyl gives lambda_new <= lambda_old + lambda(B), and the whole
 * system's Gershgorin bound caps it too. It is pessimistic (gallbladder: 6
 * sub-steps become up to 15) for a few steps: model_mass_spring_refine(),
 * called between steps, runs the power iteration a few iterations at a
 * time from the last dominant vector (kept by model_mass_spring_prepare(),
 * which costs one power iteration and 2 x 3 doubles per node, so it is for
 * models that will be cut) and, once converged (about 21 iterations), sets
 * the sub-steps from the estimate (with mass_spring_eigen_bounds' 2 %
 * margin, never above the bound after the change). Without prepare, commit
 * runs a cold estimate at once. */
#ifndef VISCERA_MODEL_MASS_SPRING_H
#define VISCERA_MODEL_MASS_SPRING_H

#include <stddef.h>
#include <stdint.h>

#include "physics/mass_spring.h"
#include "physics/model.h"

/* The force system of a mass_spring_surface model; NULL for any other model
 * (mass_spring_tet included: its surface is embedded, not simulated). */
mass_spring_t *model_mass_spring_surface_system(model_t *m);
/* See above. with_f_res also allocates the residual force array. Returns 0
 * or -1 with err (OOM; the model is unchanged and still steps). */
int model_mass_spring_reserve(model_t *m, size_t cap, int with_f_res, verr_t *err);
/* See above. Returns 0, or -1 with err: then the model is in an undefined
 * state only if the error is OOM while rebuilding springs (reported). */
int model_mass_spring_commit(model_t *m, size_t n, const uint32_t *old_to_new, size_t old_n, const uint32_t *tris,
                             size_t ntris, verr_t *err);
/* See above. Returns 0 or -1 with err (OOM). */
int model_mass_spring_prepare(model_t *m, verr_t *err);
/* See above: up to `iterations` power iterations of a pending re-estimate.
 * Returns 1 when it finished (sub-steps set from it), 0 when none is pending
 * or it goes on, -1 with err when the sub-steps could not be chosen. */
int model_mass_spring_refine(model_t *m, int iterations, verr_t *err);

#endif
