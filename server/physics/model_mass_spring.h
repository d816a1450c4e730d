/* SPDX-License-Identifier: Apache-2.0 */
/* model_mass_spring: what the surface mass-spring model (mass_spring_surface)
 * does with its topology edits, and its force system for tests.
 *
 * Topology edits (model.h edit, kind MODEL_EDIT_SURFACE; cutting/ms_cut.h is
 * the cutter). Protocol: reserve(m, cap) makes
 * room for cap nodes (allocates only when cap exceeds the capacity, then
 * grows it by half again, so a long cut reallocates a few times, never per
 * step); the caller then writes n <= cap nodes into the arrays of nodes()
 * (x, v, x_rest, mass, inv_mass, f_res: re-read after reserve) and calls
 * commit(), which takes the new triangles, rebuilds the
 * springs, re-chooses the sub-steps from the stability bound (new springs
 * and nodes change it) and increments m->topology_version. old_to_new maps
 * the old_n nodes before the change to their new index (UINT32_MAX: deleted;
 * survivors keep their order); nodes after the survivors are new. A failed
 * commit leaves the model in an undefined state only if the error is OOM
 * while rebuilding springs (reported); a failed reserve leaves it unchanged.
 *
 * The stability bound after the change is available at once, as safe as the
 * one before, without a power iteration (10-20 ms at 5k nodes: a stall):
 * with equal masses K_new = A + B, A the old K less the cut springs and
 * deleted nodes (largest eigenvalue at most the old one), B the springs
 * touching new nodes and their home springs, capped by B's Gershgorin
 * bound; Weyl gives lambda_new <= lambda_old + lambda(B), and the whole
 * system's Gershgorin bound caps it too. It is pessimistic (gallbladder: 6
 * sub-steps become up to 15) for a few steps: refine(), called between
 * steps, runs the power iteration a few iterations at a
 * time from the last dominant vector (kept by prepare(),
 * which costs one power iteration and 2 x 3 doubles per node, so it is for
 * models that will be cut) and, once converged (about 21 iterations), sets
 * the sub-steps from the estimate (with mass_spring_eigen_bounds' 2 %
 * margin, never above the bound after the change). Without prepare, commit
 * runs a cold estimate at once. */
#ifndef VISCERA_MODEL_MASS_SPRING_H
#define VISCERA_MODEL_MASS_SPRING_H

#include "physics/mass_spring.h"
#include "physics/model.h"

/* The force system of a mass_spring_surface model; NULL for any other model
 * (mass_spring_tet included: its surface is embedded, not simulated). */
mass_spring_t *model_mass_spring_surface_system(model_t *m);

/* implicit_pcg diagnostics of a mass-spring model (surface or tet): the
 * conjugate-gradient iterations and implicit steps since creation. 0, or
 * -1 for another model or integrator. */
int model_mass_spring_cg_counts(const model_t *m, uint64_t *iterations, uint64_t *steps);

/* Regional sleeping's counters (physics/ms_regions.h) of a
 * mass_spring_surface model: since creation, the sub-steps run with it,
 * the node updates (nodes integrated, summed over those sub-steps), the
 * blocks of 4 springs evaluated, wakes and sleeps of single nodes, builds
 * (creation, topology changes); and the nodes awake now. 0, or -1 when the
 * model does not sleep by regions (another model or integrator, or
 * solver.region_force 0). */
typedef struct ms_region_counts {
  uint64_t substeps, node_updates, block_evals, wakes, sleeps, builds, sleeper_checks;
  size_t awake, nodes, springs;
} ms_region_counts_t;
int model_mass_spring_region_counts(const model_t *m, ms_region_counts_t *out);
/* The regional sleeping state itself (read-only, per node: awake, xs), for
 * tests; NULL as above or before the first step. */
struct ms_regions;
const struct ms_regions *model_mass_spring_regions(const model_t *m);

#endif
