/* SPDX-License-Identifier: Apache-2.0 */
/* organ_rt: one organ of the running scene (scene_runtime.h): its model,
 * the collision tree over its contact surface, the topology it was last
 * rebuilt for, and whether it sleeps. */
#ifndef VISCERA_ORGAN_RT_H
#define VISCERA_ORGAN_RT_H

#include <stdint.h>

#include "collision/aabb_tree.h"
#include "mesh.h"
#include "physics/model.h"
#include "runtime/organ_sleep.h"
#include "runtime/vertex_cull.h"
#include "scene.h"

/* An organ: its model (model.h) owns the state. Everything that touches
 * the organ from outside (proxies, contact patch, publishing) uses the
 * model's surface: surf_x, surf_rest, surf_tris, nsurf. */
struct runtime;

typedef struct organ_rt {
  const scene_organ_t *cfg;
  uint32_t id;
  struct runtime *rt;  /* back pointer for the model's contact hook */
  mesh_t rest;         /* the imported mesh after scale and position (and mesh_admit's repairs) */
  char mesh_note[200]; /* what mesh_admit repaired, "" when nothing */
  model_t *model;      /* sub-steps and stable dt live in the model */
  double patch_radius; /* m, contact patch radius: max(2 tool radius, 1.5 mean surface edge) */
  aabb_tree_t tree;    /* over the model's contact surface, refit after every step */
  vertex_cull_t cull;  /* the surface vertices near a box, through tree (vertex_cull.h) */
  double *vn_rest;     /* unit vertex normals of the rest surface (force shading, proxy.h) */
  uint64_t rollbacks;
  uint32_t rollback_run; /* consecutive rolled-back steps (scene_runtime.h RUNTIME_ROLLBACK_RESET) */
  uint64_t rest_resets;  /* times the organ was put back to rest after such a run */
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

#endif
