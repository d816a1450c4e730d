/* SPDX-License-Identifier: Apache-2.0 */
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
#include "tet_mesh.h"
#include "verr.h"

typedef struct model model_t;
struct state_blob; /* common/state_blob.h */

/* ---- topology edits: what a cutter (server/cutting/) reads and changes ----
 *
 * Physics knows nothing of cutting: a cutter is an object of the cutting
 * layer, created given the model and owned by whoever drives it (the
 * runtime's cut phase keeps one per organ, runtime/step_cut.c), and it acts
 * on the model only through model_ops_t.edit. Two kinds of model can be
 * edited:
 *   MODEL_EDIT_SURFACE  the nodes are the surface (mass_spring_surface). The
 *                       cutter reserves room (reserve), rewrites the nodes
 *                       in place through the arrays of nodes() (re-read
 *                       after reserve: they may move), then commits the new
 *                       node count, the old-to-new node map and the new
 *                       triangles. prepare/refine keep the stability bound
 *                       after a commit cheap (optional).
 *   MODEL_EDIT_TETS     a tetrahedral mesh with an embedded surface
 *                       (pbd/xpbd). The cutter copies the mesh from nodes(),
 *                       edits its own copy, and commits a whole new mesh
 *                       (nodes, tetrahedra, boundary triangles, attributes);
 *                       the model rebuilds its solver and surface from it.
 * A commit increments topology_version (model.h's contract below) and
 * changes the model only when it succeeds. */
typedef enum { MODEL_EDIT_SURFACE = 1, MODEL_EDIT_TETS = 2 } model_edit_kind_t;

/* The model's nodes as a cutter sees them (pointers into the model, valid
 * until the next reserve or commit). */
typedef struct model_nodes {
  size_t n, cap;           /* nodes, and the room the arrays have (SURFACE) */
  double *x, *v, *x_rest;  /* 3 cap */
  double *mass, *inv_mass; /* cap, kg and 1/kg (inv_mass 0: fixed node) */
  double *f_res;           /* 3 cap, residual forces (SURFACE; NULL until reserved with them) */
  double *f_ext;           /* 3 cap, external forces of the current sub-step */
  size_t ntets;            /* TETS: tetrahedra, 4 node indices each */
  const uint32_t *tets;
  double mass_total;     /* kg, the material's total mass */
  double edge_stiffness; /* N/m, the material's edge spring stiffness (SURFACE) */
} model_nodes_t;

/* A new topology. SURFACE: n nodes written in place, old_to_new maps the
 * old_n nodes before the edit to their new index (UINT32_MAX: deleted;
 * survivors keep their order, new nodes follow them), tris over the new
 * nodes. TETS: the nodes (x, v, x_rest: 3 n; fixed: n; attr: 2 n texture
 * coordinates) and tetrahedra (4 ntets) of the new mesh, and its boundary
 * triangles over node indices (outward); the model copies what it keeps. */
typedef struct model_topology {
  size_t n;
  const uint32_t *old_to_new;
  size_t old_n;
  const double *x, *v, *x_rest, *attr;
  const uint8_t *fixed;
  size_t ntets;
  const uint32_t *tets;
  size_t ntris;
  const uint32_t *tris;
} model_topology_t;

typedef struct model_edit_ops {
  model_edit_kind_t kind;
  void (*nodes)(model_t *m, model_nodes_t *out);
  /* SURFACE: the spring (edge) count and the mean and largest rest length of
   * the edges, m. TETS: may be NULL. */
  size_t (*rest_edges)(const model_t *m, double *mean, double *max);
  /* SURFACE: room for cap nodes (with_f_res: the residual force array too).
   * 0, or -1 with err (the model unchanged and still steps). */
  int (*reserve)(model_t *m, size_t cap, int with_f_res, verr_t *err);
  /* 0, or -1 with err (see model_mass_spring.h and pbd.h for what a failed
   * commit leaves). */
  int (*commit)(model_t *m, const model_topology_t *t, verr_t *err);
  /* Optional (NULL: nothing to do): keep what makes the stability bound
   * after a commit cheap; refine it between steps, `iterations` at a time
   * (1: finished, 0: none pending or going on, -1 with err). */
  int (*prepare)(model_t *m, verr_t *err);
  int (*refine)(model_t *m, int iterations, verr_t *err);
} model_edit_ops_t;

typedef struct model_ops {
  const char *name; /* the scene file's model name */
  /* One scene step of length h (sub-steps inside). Returns 0, or -1 when
   * the step produced a non-finite state and was rolled back (state as
   * before the call; rollbacks counted). Every model's step goes through
   * the one guard of physics/model_guard.h. */
  int (*step)(model_t *m, double h);
  void (*destroy)(model_t *m);
  /* Total energy (J) where the model defines one, NAN otherwise. */
  double (*energy)(const model_t *m);
  /* The live accuracy figure published per organ (kind in error_kind). */
  double (*error_estimate)(const model_t *m);
  /* Adds force f (N) at surface vertex i for the current sub-step. */
  void (*add_surface_force)(model_t *m, uint32_t i, const double f[3]);
  /* Optional (NULL: the model integrates tool forces explicitly and keeps
   * the stiffest tool in its stability bound). Declares that forces just
   * added by the hook include a tool spring of stiffness k (N/m) acting
   * as -w_j f on surface vertices wi[j] (nw of them), with f = k (P - d)
   * and P = sum_l b_l surf_x[bi[l]] + offset (nb of them), so the model
   * may integrate its stiffness implicitly (physics/coupling.h) for this
   * sub-step. A model that does (model_t.implicit_tools set) leaves
   * tool_stiffness out of its bound, so whoever drives it declares every
   * stiff spring it adds; the others ignore the call. */
  void (*add_surface_coupling)(model_t *m, double k, size_t nw, const uint32_t *wi, const double *w, size_t nb,
                               const uint32_t *bi, const double *b);
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
   * 0, or -1 with err. A model whose cut topology is held by its cutter
   * (MODEL_EDIT_TETS, below) leaves both NULL: the cutter saves and
   * restores it (cutting/tet_model_cut.h). */
  int (*save_topology)(const model_t *m, struct state_blob *b);
  int (*restore_topology)(model_t *m, struct state_blob *b, size_t nnodes, const double *x, const double *v,
                          verr_t *err);
  /* Topology edits (cutting, above), NULL for a model that cannot be cut. */
  const model_edit_ops_t *edit;
  /* Anchors across a refinement, optional (models whose surface refines
   * and coarsens in place: adaptive_mass_spring). surface_anchor(m, tri)
   * names the part of the surface that holds triangle tri and outlives a
   * topology change (UINT32_MAX: none); after the change surface_locate
   * returns the triangle of the current surface inside that part nearest
   * to p, with the barycentric coordinates of p's closest point (UINT32_MAX:
   * none). The runtime re-attaches a contact through them
   * (runtime/topology_follow.c). */
  uint32_t (*surface_anchor)(const model_t *m, uint32_t tri);
  uint32_t (*surface_locate)(const model_t *m, uint32_t anchor, const double p[3], double bary[3]);
  /* Optional (NULL: not known). From the hook, inside a step: the surface
   * vertices that may have moved since the step began (each once, any
   * order) in *idx (the model's memory, valid until it continues), and
   * their count; SIZE_MAX when the model cannot tell in this step. Lets
   * the runtime trust the collision tree refit before the step for every
   * other vertex (runtime/vertex_cull.h). */
  size_t (*surface_moved)(const model_t *m, const uint32_t **idx);
  /* Optional (NULL: not known). After a step, until the next step or a
   * write from outside (model_note_outside_write): the surface vertices
   * that step may have moved (each once, any order; rolled back or not) in
   * *idx (the model's memory), and their count; SIZE_MAX when the model
   * cannot tell. Every other surface vertex is bit for bit where it was
   * before the step, so the runtime refits the collision tree and watches
   * for rest over these alone instead of the whole surface. */
  size_t (*last_step_moved)(const model_t *m, const uint32_t **idx);
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
  double *surf_x;            /* 3 nsurf, current */
  const double *surf_rest;   /* 3 nsurf */
  const uint32_t *surf_tris; /* 3 nsurf_tris */
  /* Stepping. */
  int substeps;       /* per scene step */
  int implicit_tools; /* 1: tool springs declared through add_surface_coupling are implicit */
  double stable_dt;   /* s, the bound the sub-steps were chosen from (INFINITY: unconditionally stable) */
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
  /* Writes from outside: whoever writes x, v or surf_x other than through
   * ops->step (a reset to rest, a checkpoint restore, a test) calls
   * model_note_outside_write afterwards. A model may trust between steps
   * that a state it did not write is unchanged while this stays put
   * (regional sleeping then need not look at its sleeping nodes). */
  uint64_t outside_writes;
  void (*hook)(model_t *m, void *ctx);
  void *hook_ctx;
};

/* The state (x, v or surf_x) was written from outside the model's step. */
static inline void model_note_outside_write(model_t *m) { m->outside_writes++; }

/* Everything a model constructor gets. tool_stiffness (N/m) is the stiffest
 * tool spring that may act on the surface: explicit schemes include it in
 * their stability bound unless they integrate tool springs implicitly
 * (model_ops_t.add_surface_coupling). */
typedef struct model_params {
  const scene_organ_t *cfg;
  const mesh_t *surface; /* after scale and position; the model copies what it keeps */
  double gravity[3];
  double dt; /* scene step */
  double tool_stiffness;
  /* The organ's own tetrahedra (scene key `volume`), after scale and
   * position; NULL: volumetric models fill the surface themselves. Only
   * mass_spring_tet, pbd and xpbd read it; they copy what they keep. */
  const tet_mesh_t *volume;
} model_params_t;

/* Dispatches on p->cfg->model; errors name the organ and what is wrong. */
model_t *model_create(const model_params_t *p, verr_t *err);
static inline void model_destroy(model_t *m) {
  if (m) m->ops->destroy(m);
}

#endif
