/* model: the one interface every deformation model implements, so the
 * server runtime, the tests and the benchmarks treat them alike.
 *
 * A model simulates `nnodes` nodes (surface vertices, or tetrahedral mesh
 * nodes) and presents a render/contact surface of `nsurf` vertices with the
 * organ's triangles. For surface models the surface IS the node set
 * (surf_x == x); volumetric models embed the surface (e.g. barycentrically in
 * tetrahedra) and update surf_x after each step.
 *
 * Life cycle: model_create() (server/physics/model_registry.c) picks the
 * implementation by scene_organ_t.model and allocates everything once;
 * step() allocates nothing. Contact coupling: before every sub-step the
 * model calls hook(m, hook_ctx) if set; the hook applies forces to surface
 * vertices with add_surface_force(), valid for that sub-step only.
 * Not thread-safe: one physics thread owns a model. */
#ifndef VISCERA_MODEL_H
#define VISCERA_MODEL_H

#include <stddef.h>
#include <stdint.h>

#include "mesh.h"
#include "scene.h"
#include "verr.h"

typedef struct model model_t;
struct state_blob; /* common/state_blob.h */

typedef struct model_ops {
  const char *name; /* the scene file's model name */
  /* One scene step of length h (sub-steps inside). Returns 0, or -1 when
   * the step produced a non-finite state and was rolled back (state as
   * before the call). */
  int (*step)(model_t *m, double h);
  void (*destroy)(model_t *m);
  /* Total energy (J) where the model defines one, NAN otherwise. */
  double (*energy)(const model_t *m);
  /* The live accuracy figure published per organ (kind in error_kind). */
  double (*error_estimate)(const model_t *m);
  /* Adds force f (N) at surface vertex i for the current sub-step. */
  void (*add_surface_force)(model_t *m, uint32_t i, const double f[3]);
  /* Checkpoints of a changed topology (runtime/checkpoint_state.h), optional: a
   * model without them cannot be checkpointed once its topology_version is
   * above 0 (the checkpoint says so and keeps the last one it could write).
   * save_topology appends to b everything the model needs to rebuild its
   * nodes and surface as they are (node positions and velocities excepted:
   * the checkpoint stores those for every model). restore_topology, on a
   * model freshly built from the same scene, rebuilds from those bytes
   * (untrusted: every count bounded, every index checked), then takes the
   * node positions x and velocities v (3 nnodes each; a rebuild to another
   * node count is refused) and
   * brings its surface to them; it changes m only when all succeeded.
   * Afterwards nodes, surface and topology_version are as when saved.
   * 0, or -1 with err. */
  int (*save_topology)(const model_t *m, struct state_blob *b);
  int (*restore_topology)(model_t *m, struct state_blob *b, size_t nnodes, const double *x, const double *v,
                          verr_t *err);
} model_ops_t;

struct model {
  const model_ops_t *ops;
  const char *error_kind; /* "max_edge_strain", "constraint_residual", "volume_error", "energy_drift" */
  /* Simulated nodes. */
  size_t nnodes;
  double *x, *v;        /* 3 nnodes */
  const double *x_rest; /* 3 nnodes */
  size_t ntets;         /* 0 for surface models: they allocate no tetrahedra */
  /* Render / contact surface. */
  size_t nsurf, nsurf_tris;
  double *surf_x;             /* 3 nsurf, current */
  const double *surf_rest;    /* 3 nsurf */
  const uint32_t *surf_tris;  /* 3 nsurf_tris */
  /* Stepping. */
  int substeps;     /* per scene step */
  double stable_dt; /* s, the bound the sub-steps were chosen from (INFINITY: unconditionally stable) */
  uint64_t rollbacks;
  /* Topology of the surface: 0 at creation. A model that changes its surface
   * (adaptive refinement, cutting) increments it after it has updated nsurf,
   * nsurf_tris, surf_x, surf_rest and surf_tris (the pointers may change then,
   * and only then). A cut may also replace the nodes (nnodes, x, v, x_rest,
   * ntets): whoever keeps node or surface pointers or indices re-reads them
   * when the version moves. The runtime compares it after every step and
   * rebuilds what depends on the surface (collision tree, proxies, grasps,
   * publisher). */
  uint32_t topology_version;
  void (*hook)(model_t *m, void *ctx);
  void *hook_ctx;
};

/* Everything a model constructor gets. tool_stiffness (N/m) is the stiffest
 * tool spring that may act on the surface: explicit schemes include it in
 * their stability bound. */
typedef struct model_params {
  const scene_organ_t *cfg;
  const mesh_t *surface; /* after scale and position; the model copies what it keeps */
  double gravity[3];
  double dt;             /* scene step */
  double tool_stiffness;
} model_params_t;

/* Dispatches on p->cfg->model; errors name the organ and what is wrong. */
model_t *model_create(const model_params_t *p, verr_t *err);
static inline void model_destroy(model_t *m) {
  if (m) m->ops->destroy(m);
}

#endif
