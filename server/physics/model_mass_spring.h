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
 * and nodes change it) and increments m->topology_version. */
#ifndef VISCERA_MODEL_MASS_SPRING_H
#define VISCERA_MODEL_MASS_SPRING_H

#include <stddef.h>
#include <stdint.h>

#include "mass_spring.h"
#include "model.h"

/* The force system of a mass_spring_surface model; NULL for any other model
 * (mass_spring_tet included: its surface is embedded, not simulated). */
mass_spring_t *model_mass_spring_surface_system(model_t *m);
/* See above. with_f_res also allocates the residual force array. Returns 0
 * or -1 with err (OOM; the model is unchanged and still steps). */
int model_mass_spring_reserve(model_t *m, size_t cap, int with_f_res, verr_t *err);
/* See above. Returns 0, or -1 with err: then the model is in an undefined
 * state only if the error is OOM while rebuilding springs (reported). */
int model_mass_spring_commit(model_t *m, size_t n, const uint32_t *tris, size_t ntris, verr_t *err);

#endif
