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

#include "collision/aabb_tree.h"
#include "haptics/proxy.h"
#include "interaction/events.h"
#include "interaction/grasp.h"
#include "interaction/stone.h"
#include "interaction/tasks.h"
#include "mesh.h"
#include "organ_sleep.h"
#include "physics/model.h"
#include "scene.h"
#include "tool_input.h"
#include "verr.h"

/* An organ: its model (model.h) owns the state. Everything that touches
 * the organ from outside (proxies, contact patch, publishing) uses the
 * model's surface: surf_x, surf_rest, surf_tris, nsurf. */
struct runtime;

typedef struct organ_rt {
  const scene_organ_t *cfg;
  uint32_t id;
  struct runtime *rt;  /* back pointer for the model's contact hook */
  mesh_t rest;         /* the imported mesh after scale and position */
  model_t *model;      /* sub-steps and stable dt live in the model */
  double patch_radius; /* m, contact patch radius: max(2 tool radius, 1.5 mean surface edge) */
  aabb_tree_t tree;    /* over the model's contact surface, refit after every step */
  double *vn_rest;     /* unit vertex normals of the rest surface (force shading, proxy.h) */
  uint64_t rollbacks;
  /* The model topology_version the tree, surface view, proxies and patches
   * were last rebuilt for (topology_follow.h). The server polls it: when it
   * differs from what it last published, a new keyframe is due. */
  uint32_t topology_version;
  uint64_t topology_changes; /* rebuilds so far */
  double last_follow_us;     /* the last rebuild's time (tree, surface view, re-attach), us */
  /* Sleeping at rest (organ_sleep.h); unused (prev NULL) when the scene's
   * sleep_speed is 0. */
  organ_sleep_t sleep;
} organ_rt_t;

#define TOOL_PATCH_MAX 128

typedef struct tool_rt {
  const scene_tool_t *cfg;
  int active;       /* a valid command has been received */
  double device[3]; /* commanded tip, m */
  double max_force; /* N: min(tool, device capability) */
  proxy_t proxy;
  double force[3];   /* N on the tool, last step */
  double peak_force; /* N since start */
  /* Contact patch: the tissue vertices that share the reaction force, with
   * weights summing to 1. A rigid tip presses an area, not three vertices;
   * spreading the load keeps the dent smooth and the contact normal steady. */
  size_t npatch;
  uint32_t patch[TOOL_PATCH_MAX];
  double patch_w[TOOL_PATCH_MAX];
  /* Interactions (interaction/tool_actions.c). */
  uint32_t buttons;      /* ToolCommand.buttons, bit 0 = jaws closed */
  uint32_t prev_buttons; /* at the previous step: grasping happens on closing */
  grasp_t grasp;         /* grasper: tissue held */
  int stone;             /* extractor: stone held, or -1 */
  double first_cmd_time; /* s of simulated time of the first command, -1 before */
  double axis[3];        /* unit shaft direction from the tip (command orientation applied to +z) */
  /* What the tool's client is told (ContactFeedback): the tip the hand
   * feels (god-object, stone surface, grasp pull or tool-tool contact),
   * normal and whether anything touches; organ -1 for stones and tools. */
  int fb_contact, fb_organ;
  double fb_pos[3], fb_normal[3];
} tool_rt_t;

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
  struct scalpel *scalpel; /* cutting (interaction/scalpel.h); NULL in a scene without a scalpel */
  uint64_t steps;
  double sim_time;       /* s */
  size_t organs_stepped; /* organs stepped by the last runtime_step (the others slept) */
} runtime_t;

/* Imports every organ mesh and builds its model (model_create: the model
 * chooses its sub-steps from the scene's dt and the stiffest tool). Errors
 * name the scene file, the organ's line and the organ. */
int runtime_init(runtime_t *rt, const scene_t *scene, verr_t *err);
void runtime_destroy(runtime_t *rt);

/* Applies a validated command for tool `t`. */
void runtime_set_tool(runtime_t *rt, size_t t, const double pos[3], double device_max_force);
/* The command's buttons (bit 0: close the jaws), applied at the next step. */
void runtime_set_buttons(runtime_t *rt, size_t t, uint32_t buttons);
/* The command's orientation (unit quaternion w, x, y, z): the shaft axis. */
void runtime_set_orientation(runtime_t *rt, size_t t, const double q[4]);
/* Tool no longer driven (client gone): releases contact, stops acting. */
void runtime_release_tool(runtime_t *rt, size_t t);

/* After a model's topology was restored from a checkpoint (checkpoint.c):
 * rebuilds what depends on its surface, as after a cut in a step (tree,
 * proxies, normals; grasps of it released). */
void runtime_topology_restored(runtime_t *rt, size_t organ);

/* One scene step of scene.dt: contact, then physics. Returns the number of
 * organs whose step was rolled back because it produced NaN/Inf. With the
 * scene's sleep_speed > 0 an organ at rest with nothing within reach is
 * skipped (organ_sleep.h; organs_stepped tells how many were stepped). */
int runtime_step(runtime_t *rt);

#endif
