/* SPDX-License-Identifier: Apache-2.0 */
/* step_cut: the runtime's cut phase (scalpel_*), the scalpel tool cutting
 * organs in the live runtime (issue 5).
 *
 * A tool of kind `scalpel` whose ToolCommand.buttons bit 0 is set is
 * cutting. Its blade is the segment from the commanded tip (the hand's
 * position, not the god-object proxy: a blade goes into the tissue) along
 * the tool axis (shaft.h: the command's orientation applied to +z) over the
 * tool's `blade_length` (scene.h). While cutting, the scalpel leaves the
 * god-object proxy and its shaft does not push tissue (the blade parts it);
 * with the button released it touches like a probe.
 *
 * Per organ, after that organ's model step and before the runtime compares
 * topology_version (scene_runtime.c: never inside the sub-step hook, and
 * the runtime's topology follow-up runs at once after a change):
 *   - tetrahedral organs (model.h edit kind MODEL_EDIT_TETS: pbd / xpbd):
 *     tet_model_cut_advance(tip, handle) every step while the blade's box
 *     overlaps the organ's current bounds (grown by the blade radius);
 *     tet_model_cut_end when the blade leaves them, the button is released
 *     or the tool is released (client lost: its buttons read 0);
 *   - surface organs (edit kind MODEL_EDIT_SURFACE: mass_spring_surface):
 *     ms_cut_step every step, with the blade
 *     (cylinder of the tool's `radius`, handle -> tip) while cutting and with
 *     a parked blade (a point outside every organ) otherwise, because the
 *     cutter refines its stability estimate over the steps after a cut;
 *     ms_cut_end when the button or the tool is released;
 *   - any other model: the scalpel only touches (the models have no cutter).
 * One scalpel cuts an organ at a time (the first one, by tool order, whose
 * blade reaches it); others touch it like probes meanwhile.
 *
 * Cutting structures exist only in a scene with a scalpel: scalpel_init
 * creates one cutter per cuttable organ, owned here and destroyed before
 * the models (a tet_model_cut with the mesh copied at load, or an ms_cut),
 * and nothing (rt->scalpel stays NULL) otherwise. The models know nothing
 * of them: the cutters act through model.h's edit operations.
 *
 * Checkpoints: a tetrahedral organ's cut topology is its cutter's mesh, so
 * the cutter saves and restores it (scalpel_save_topology /
 * scalpel_restore_topology, used by runtime/checkpoint_state.c for the
 * organs scalpel_owns_topology names); other models save their own
 * (model.h save_topology).
 *
 * Events (rt->events): IEV_CUT_BEGIN when a cut first touches tissue (pbd:
 * the blade crossed a tetrahedron edge; ms: its axis crossed the surface;
 * value = surface vertices then), IEV_CUT_END when it ends (value =
 * topology changes the cut made). A refused call (bad blade, out of memory,
 * a segment the ms cutter could not apply) is counted and its message kept
 * (first ones logged by the caller through scalpel_take_error), never fatal:
 * the model keeps simulating its last topology. */
#ifndef VISCERA_STEP_CUT_H
#define VISCERA_STEP_CUT_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "runtime/scene_runtime.h"
#include "state_blob.h"
#include "verr.h"

typedef struct scalpel_organ_stats {
  int can_cut;   /* a model with topology edits (pbd/xpbd or mass_spring_surface) */
  uint64_t cuts; /* cuts that touched tissue */
  uint64_t topology_changes;
  uint64_t refused;                    /* cutter calls that returned an error */
  uint64_t calls;                      /* cutter calls with the blade in (pbd) or every step (ms) */
  double call_us_sum, call_us_max;     /* wall time of those calls, us */
  uint64_t change_calls;               /* calls that changed the topology */
  double change_us_sum, change_us_max; /* ... and their wall time, us */
  size_t nsurf_initial;
  size_t max_keyframe_bytes; /* positions + triangles (float, uint32) of the largest surface after a cut */
} scalpel_organ_stats_t;

/* Creates the cutting structures when the scene has a scalpel (rt->scalpel
 * stays NULL otherwise). Call after the organs are built. Errors name the
 * scene line of the organ or tool. */
int scalpel_init(runtime_t *rt, verr_t *err);
void scalpel_destroy(runtime_t *rt);

/* Whether tool t is a scalpel with its button pressed (it leaves the
 * god-object proxy and its shaft does not push). */
int scalpel_cutting(const runtime_t *rt, size_t t);

/* After organ `organ`'s model step: advances or ends its cut (see above).
 * May change the model's topology; the caller follows it. */
void scalpel_after_organ_step(runtime_t *rt, size_t organ);

/* The ms cutter's incision width of the organ (m, mean and max over the
 * lips); 0 when there is none or the organ is not mass_spring_surface. */
size_t scalpel_incision_width(const runtime_t *rt, size_t organ, double *mean, double *max);

const scalpel_organ_stats_t *scalpel_stats(const runtime_t *rt, size_t organ);
/* Whether a cutting structure exists for the organ (tests). */
int scalpel_has_cutter(const runtime_t *rt, size_t organ);

/* Whether organ's changed topology is held by its cutter (a tetrahedral
 * organ in a scene with a scalpel) rather than by its model. */
int scalpel_owns_topology(const runtime_t *rt, size_t organ);
/* Appends that topology (the cutter's bytes, tet_model_cut_save) to b: 0,
 * or -1 (nothing to save, out of memory). */
int scalpel_save_topology(const runtime_t *rt, size_t organ, state_blob_t *b);
/* Restores it into the organ's model (tet_model_cut_restore): 0, or -1
 * with err (the model unchanged). The caller follows the topology. */
int scalpel_restore_topology(runtime_t *rt, size_t organ, state_blob_t *b, size_t nnodes, const double *x,
                             const double *v, verr_t *err);

/* The message of the latest refused call not yet taken, with the running
 * count of refusals (0: none new). */
uint64_t scalpel_take_error(runtime_t *rt, char *msg, size_t len);

/* One `CUT organ=...` line per organ a scalpel may cut (the server's exit
 * lines). */
void scalpel_print_summary(const runtime_t *rt, FILE *f);

#endif
