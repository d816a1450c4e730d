/* SPDX-License-Identifier: Apache-2.0 */
/* scene_runtime: the simulated scene without any networking: organs with
 * their deformation models, tools with their haptic proxies, and the fixed
 * step. The server wraps it with DDS; benchmarks and tests drive it directly.
 *
 * runtime_init builds only what the scene needs (one model per organ, one
 * proxy per tool). runtime_step allocates nothing, except after a step in
 * which a model changed its surface topology (topology_follow.h: the tree
 * is rebuilt, contacts re-attached). Single-threaded. */
#ifndef VISCERA_SCENE_RUNTIME_H
#define VISCERA_SCENE_RUNTIME_H

#include <stddef.h>
#include <stdint.h>

#include "haptics/proxy.h"
#include "interaction/events.h"
#include "interaction/stone.h"
#include "interaction/tasks.h"
#include "runtime/organ_rt.h"
#include "runtime/tool_command.h"
#include "runtime/tool_rt.h"
#include "scene.h"
#include "verr.h"

typedef struct runtime {
  scene_t scene;
  size_t norgans, ntools;
  organ_rt_t organs[SCENE_MAX_ORGANS];
  tool_rt_t tools[SCENE_MAX_TOOLS];
  proxy_surface_t surfaces[SCENE_MAX_ORGANS];
  tool_workspace_t workspace;
  size_t nstones;
  stone_t stones[SCENE_MAX_OBJECTS];
  size_t ntasks;
  task_rt_t tasks[SCENE_MAX_TASKS];
  iev_queue_t events;      /* interaction events; the caller drains (clears n) */
  struct scalpel *scalpel; /* cutting (runtime/step_cut.h); NULL in a scene without a scalpel */
  uint64_t steps;
  double sim_time;       /* s */
  size_t organs_stepped; /* organs stepped by the last runtime_step (the others slept) */
  /* Bit i: organ i was put back to rest by the last runtime_step, after
   * RUNTIME_ROLLBACK_RESET consecutive rolled-back steps (organ_rt.h
   * rollback_run); the server says so (event and log). */
  uint32_t organs_reset;
  /* The vertex culls of the contact patch and the shafts' node test
   * (runtime/vertex_cull.h): how often each culled or scanned every vertex,
   * and two knobs for tests: force_scan (1: always scan, the reference;
   * the tree refit and the organ sleep watch then look at every vertex too)
   * and patch_scale, shaft_scale (1 at init; a test shrinks the culls'
   * radii with them to show that a cull short of its proven radius misses
   * vertices). */
  struct {
    uint64_t patch_culls, patch_scans, shaft_culls, shaft_scans;
    int force_scan;
    double patch_scale, shaft_scale;
  } cull;
} runtime_t;

/* Consecutive rolled-back steps after which an organ is put back to rest
 * (nodes at their rest positions, velocities zero): a state the guard
 * restores but that can never step (a velocity that overflows, a contact
 * the material cannot take) would otherwise freeze the organ for good. 200
 * steps is 0.2 s at the default 1 kHz: long enough that a passing spike
 * never triggers it. */
#define RUNTIME_ROLLBACK_RESET 200

/* Imports every organ mesh and builds its model (model_create: the model
 * chooses its sub-steps from the scene's dt and the stiffest tool). Errors
 * name the scene file, the organ's line and the organ. */
int runtime_init(runtime_t *rt, const scene_t *scene, verr_t *err);
void runtime_destroy(runtime_t *rt);

/* Applies a validated command to tool `t` (runtime/tool_command.h: a
 * checked tool_cmd_t as tool_input_t): it becomes the tool's cmd, drives its
 * tip, jaws and shaft from the next step on. */
void runtime_command_tool(runtime_t *rt, size_t t, const tool_input_t *in);
/* Parts of a command (re-simulation and tests drive tools this way): */
/* The tip and the device's force capability; makes the tool active. */
void runtime_set_tool(runtime_t *rt, size_t t, const double pos[3], double device_max_force);
/* The command's buttons (bit 0: close the jaws), applied at the next step. */
void runtime_set_buttons(runtime_t *rt, size_t t, uint32_t buttons);
/* The command's orientation (unit quaternion w, x, y, z): the shaft axis. */
void runtime_set_orientation(runtime_t *rt, size_t t, const double q[4]);
/* Tool no longer driven (client gone): drops what it holds, stops acting;
 * its god-object keeps its contact for the client's return. */
void runtime_release_tool(runtime_t *rt, size_t t);

/* After a model's topology was restored from a checkpoint (checkpoint.c):
 * rebuilds what depends on its surface, as after a cut in a step (tree,
 * proxies, normals; grasps of it released). */
void runtime_topology_restored(runtime_t *rt, size_t organ);

/* One scene step of scene.dt in named phases (scene_runtime.c: inputs,
 * tools, contact, models with cut and topology, contact settle, outputs).
 * Returns the number of organs whose step was rolled back because it
 * produced NaN/Inf. With the scene's sleep_speed > 0 an organ at rest with
 * nothing within reach is skipped (organ_sleep.h; organs_stepped tells how
 * many were stepped). An organ rolled back RUNTIME_ROLLBACK_RESET steps in a
 * row is put back to rest in that step (organs_reset). */
int runtime_step(runtime_t *rt);

/* runtime_step in two halves, for a caller that answers a command before
 * the tissue moves (the session, docs/architecture.md): runtime_step(rt)
 * is exactly runtime_step_begin(rt) then runtime_step_finish(rt) (same
 * phases, same order, same results bit for bit).
 *   begin:  inputs, tools, contact (god-objects moved toward the new tips
 *           over the surfaces as they are, patches built)
 *   finish: models (with cut and topology), contact settle, time, outputs;
 *           returns what runtime_step returns. */
void runtime_step_begin(runtime_t *rt);
int runtime_step_finish(runtime_t *rt);
/* After runtime_step_begin: what each tool's client would be told if the
 * tissue did not move in this step. Fills tools[0..rt->ntools) with copies
 * of rt->tools, settles each copy's proxy on the current surfaces and runs
 * the outputs phase's feedback part on the copies (interact_feedback:
 * fb_contact, fb_organ, fb_pos, fb_normal, force; the copies' peak_force is
 * raised, not rt's). No event, no peak, no tally, no state of the step
 * changes in rt: it writes only the culls' working memory (rt->cull's
 * counters, each organ's cull scratch), which is why rt is not const. */
void runtime_feedback_preview(runtime_t *rt, tool_rt_t tools[SCENE_MAX_TOOLS]);

#endif
