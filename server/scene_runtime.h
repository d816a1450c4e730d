/* scene_runtime: the simulated scene without any networking: organs with
 * their deformation models, tools with their haptic proxies, and the fixed
 * step. The server wraps it with DDS; benchmarks and tests drive it directly.
 *
 * runtime_init builds only what the scene needs (one model per organ, one
 * proxy per tool). runtime_step allocates nothing. Single-threaded. */
#ifndef VISCERA_SCENE_RUNTIME_H
#define VISCERA_SCENE_RUNTIME_H

#include <stddef.h>
#include <stdint.h>

#include "haptics/proxy.h"
#include "mesh.h"
#include "physics/mass_spring.h"
#include "scene.h"
#include "tool_input.h"
#include "verr.h"

typedef struct organ_rt {
  const scene_organ_t *cfg;
  uint32_t id;
  mesh_t rest;       /* the imported mesh after scale and position */
  mass_spring_t ms;  /* v1: the only model */
  int substeps;      /* per scene step, from the stability bound */
  double patch_radius; /* m, contact patch radius: max(2 tool radius, 1.5 mean edge) */
  double stable_dt;  /* s, the integrator's bound including tool stiffness */
  uint64_t rollbacks;
} organ_rt_t;

#define TOOL_PATCH_MAX 128

typedef struct tool_rt {
  const scene_tool_t *cfg;
  int active;          /* a valid command has been received */
  double device[3];    /* commanded tip, m */
  double max_force;    /* N: min(tool, device capability) */
  proxy_t proxy;
  double force[3];     /* N on the tool, last step */
  double peak_force;   /* N since start */
  /* Contact patch: the tissue vertices that share the reaction force, with
   * weights summing to 1. A rigid tip presses an area, not three vertices;
   * spreading the load keeps the dent smooth and the contact normal steady. */
  size_t npatch;
  uint32_t patch[TOOL_PATCH_MAX];
  double patch_w[TOOL_PATCH_MAX];
} tool_rt_t;

typedef struct runtime {
  scene_t scene;
  size_t norgans, ntools;
  organ_rt_t organs[SCENE_MAX_ORGANS];
  tool_rt_t tools[SCENE_MAX_TOOLS];
  proxy_surface_t surfaces[SCENE_MAX_ORGANS];
  tool_workspace_t workspace;
  uint64_t steps;
  double sim_time; /* s */
} runtime_t;

/* Imports every organ mesh, builds its model and chooses sub-steps so the
 * integrator is stable at the scene's dt. Errors name the organ and file. */
int runtime_init(runtime_t *rt, const scene_t *scene, verr_t *err);
void runtime_destroy(runtime_t *rt);

/* Applies a validated command for tool `t`. */
void runtime_set_tool(runtime_t *rt, size_t t, const double pos[3], double device_max_force);
/* Tool no longer driven (client gone): releases contact, stops acting. */
void runtime_release_tool(runtime_t *rt, size_t t);

/* One scene step of scene.dt: contact, then physics. Returns the number of
 * organs whose step was rolled back because it produced NaN/Inf. */
int runtime_step(runtime_t *rt);

#endif
