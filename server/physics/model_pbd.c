/* SPDX-License-Identifier: Apache-2.0 */
/* model_pbd: the scene models "pbd" and "xpbd" behind model_t. The organ's
 * surface is filled with tetrahedra (tet_mesh_build), the solver in pbd.c
 * runs on their nodes, and the render/contact surface rides along through
 * its barycentric embedding. Messages do not name the organ: model_create
 * (model_registry.c) prefixes it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "physics/model_volume.h"
#include "physics/pbd.h"
#include "tet_mesh.h"

typedef struct model_pbd {
  model_t base; /* first, so model_t * and model_pbd_t * convert */
  pbd_t s;
  tet_mesh_t tm;
  tet_embedding_t emb;
  double *surf_x, *surf_rest;
  uint32_t *surf_tris;
  /* After the first topology edit (model.h edit, a cut) the surface is the
   * tetrahedral boundary: surf_node maps its vertices to nodes (and replaces
   * the embedding), surf_attr holds their attribute. NULL before. */
  uint32_t *surf_node;
  double *surf_attr;
  coupling_set_t cpl; /* the sub-step's tool springs as constraints (s.cpl points here) */
} model_pbd_t;

/* Sub-steps chosen when the scene leaves solver.substeps at 0: PBD and XPBD
 * are stable at any step, but XPBD converges better (alpha / h^2 grows) and
 * contact is coupled more tightly with short sub-steps; 1 ms matches the
 * haptic rate. */
#define PBD_AUTO_SUBSTEP 1e-3

/* Before every sub-step: the surface is brought to the sub-step's positions
 * so the contact hook sees where the tissue is (model.h), as the
 * mass-spring models do; without it every sub-step of a scene step saw the
 * surface of the step's start, and a contact force held that long is an
 * explicit spring at the scene rate (a penalty ground then diverged at
 * 60 Hz with any number of sub-steps). */
static void surface_from_nodes(model_pbd_t *mp, const double *x) {
  model_t *m = &mp->base;
  /* After a cut the surface is the tetrahedral boundary (surf_node); the
   * embedding describes the uncut mesh and must not be applied then. */
  if (mp->surf_node)
    for (size_t i = 0; i < m->nsurf; i++)
      memcpy(mp->surf_x + 3 * i, x + 3 * (size_t)mp->surf_node[i], 3 * sizeof(double));
  else
    tet_embedding_apply(&mp->emb, &mp->tm, x, mp->surf_x);
}

static void pbd_pre_hook(pbd_t *s, void *ctx) {
  model_t *m = ctx;
  coupling_set_clear(&((model_pbd_t *)m)->cpl);
  if (!m->hook) return;
  surface_from_nodes((model_pbd_t *)m, s->x);
  m->hook(m, m->hook_ctx);
}

static int pbd_model_step(model_t *m, double h) {
  model_pbd_t *mp = (model_pbd_t *)m;
  int rc = pbd_step(&mp->s, h, pbd_pre_hook, m);
  if (rc) m->rollbacks++;
  /* After a rollback the restored nodes are embedded again too, so the
   * surface always shows the state the model holds. */
  surface_from_nodes(mp, mp->s.x);
  return rc;
}

static void pbd_model_destroy(model_t *m) {
  model_pbd_t *mp = (model_pbd_t *)m;
  pbd_destroy(&mp->s);
  tet_mesh_free(&mp->tm);
  tet_embedding_free(&mp->emb);
  free(mp->surf_x);
  free(mp->surf_rest);
  free(mp->surf_tris);
  free(mp->surf_node);
  free(mp->surf_attr);
  coupling_set_free(&mp->cpl);
  free(mp);
}

static double pbd_model_energy(const model_t *m) {
  const model_pbd_t *mp = (const model_pbd_t *)m;
  /* PBD has no energy it minimises (its constraints are rigid up to an
   * iteration-dependent stiffness); XPBD's compliance defines one. */
  if (mp->s.p.mode != PBD_MODE_XPBD) return NAN;
  return pbd_energy(&mp->s);
}

static double pbd_model_error(const model_t *m) { return pbd_volume_error(&((const model_pbd_t *)m)->s); }

/* A surface force acts at a point inside its tetrahedron: the barycentric
 * weights spread it over the four nodes, the transpose of the embedding, so
 * the work done on the surface equals the work done on the nodes. */
static void pbd_model_add_surface_force(model_t *m, uint32_t i, const double f[3]) {
  model_pbd_t *mp = (model_pbd_t *)m;
  if (!(isfinite(f[0]) && isfinite(f[1]) && isfinite(f[2]))) return;
  if (mp->surf_node) {
    if (i < m->nsurf) pbd_add_force(&mp->s, mp->surf_node[i], f);
    return;
  }
  if (i >= mp->emb.nsurf) return;
  const uint32_t *q = mp->tm.tets + 4 * (size_t)mp->emb.tet[i];
  const double *b = mp->emb.bary + 4 * (size_t)i;
  for (int k = 0; k < 4; k++) {
    double fk[3] = {b[k] * f[0], b[k] * f[1], b[k] * f[2]};
    pbd_add_force(&mp->s, q[k], fk);
  }
}

/* A surface vertex's weight in node terms: the embedding's (or, after a
 * cut, its node's), as pbd_model_add_surface_force spreads a force. */
typedef void (*push_fn)(coupling_set_t *cs, uint32_t node, double w);
static void push_surface(model_pbd_t *mp, push_fn push, uint32_t i, double w) {
  if (mp->surf_node) {
    if (i < mp->base.nsurf) push(&mp->cpl, mp->surf_node[i], w);
    return;
  }
  if (i >= mp->emb.nsurf) return;
  const uint32_t *q = mp->tm.tets + 4 * (size_t)mp->emb.tet[i];
  const double *b = mp->emb.bary + 4 * (size_t)i;
  for (int k = 0; k < 4; k++)
    if (b[k] != 0) push(&mp->cpl, q[k], w * b[k]);
}

/* Tool springs implicitly (pbd.h, coupling.h): force weights and
 * attachment weights carried from surface vertices to nodes through the
 * embedding. */
static void pbd_model_add_coupling(model_t *m, double k, size_t nw, const uint32_t *wi, const double *w, size_t nb,
                                   const uint32_t *bi, const double *b) {
  model_pbd_t *mp = (model_pbd_t *)m;
  if (!m->implicit_tools || !isfinite(k)) return;
  coupling_begin(&mp->cpl, k);
  for (size_t j = 0; j < nw; j++) push_surface(mp, coupling_push_w, wi[j], w[j]);
  for (size_t l = 0; l < nb; l++) push_surface(mp, coupling_push_b, bi[l], b[l]);
  coupling_end(&mp->cpl);
}

static const model_edit_ops_t PBD_EDIT;

/* pbd and xpbd share every operation; only the name (and the mode the
 * model was created with) differ. A changed topology is checkpointed by
 * the cutter that made it (it holds the mesh: cutting/tet_model_cut.h), so
 * save_topology and restore_topology are not set. */
#define PBD_FAMILY_OPS(model_name)                                                                                     \
  {                                                                                                                    \
    .name = model_name, .step = pbd_model_step, .destroy = pbd_model_destroy, .energy = pbd_model_energy,              \
    .error_estimate = pbd_model_error, .add_surface_force = pbd_model_add_surface_force,                               \
    .add_surface_coupling = pbd_model_add_coupling, .edit = &PBD_EDIT                                                  \
  }
static const model_ops_t PBD_OPS = PBD_FAMILY_OPS("pbd");
static const model_ops_t XPBD_OPS = PBD_FAMILY_OPS("xpbd");

model_t *model_pbd_create(const model_params_t *p, verr_t *err) {
  const scene_organ_t *cfg = p->cfg;
  pbd_mode_t mode;
  if (!strcmp(cfg->model, "pbd"))
    mode = PBD_MODE_PBD;
  else if (!strcmp(cfg->model, "xpbd"))
    mode = PBD_MODE_XPBD;
  else {
    verr_set(err, "model '%s' is not pbd or xpbd", cfg->model);
    return NULL;
  }
  if (!(p->dt > 0) || !isfinite(p->dt)) {
    verr_set(err, "time step must be > 0 (got %g)", p->dt);
    return NULL;
  }
  const mesh_t *surf = p->surface;
  if (!surf || surf->nverts == 0 || surf->ntris == 0) {
    verr_set(err, "empty surface mesh");
    return NULL;
  }
  model_pbd_t *mp = calloc(1, sizeof *mp);
  if (!mp) {
    verr_set(err, "out of memory");
    return NULL;
  }
  verr_t sub;
  if (model_volume_obtain(p, &mp->tm, &mp->emb, err)) {
    free(mp);
    return NULL;
  }
  if (mp->emb.nsurf != surf->nverts) {
    verr_set(err, "the embedding holds %zu of %zu surface vertices", mp->emb.nsurf, surf->nverts);
    tet_mesh_free(&mp->tm);
    tet_embedding_free(&mp->emb);
    free(mp);
    return NULL;
  }
  const scene_material_t *mat = &cfg->material;
  pbd_params_t pp = {
      .mode = mode,
      .mass = mat->mass,
      .distance_stiffness = mat->distance_stiffness,
      .volume_stiffness = mat->volume_stiffness,
      .distance_compliance = mat->distance_compliance,
      .volume_compliance = mat->volume_compliance,
      .home_stiffness = mat->home_stiffness,
      .damping = mat->home_damping,
      .gravity = {p->gravity[0], p->gravity[1], p->gravity[2]},
      .substeps = cfg->solver.substeps,
      .iterations = cfg->solver.iterations,
      /* The scene's stiffness means "error left after a sub-step", not
       * "per iteration", so it does not change with solver.iterations. */
      .stiffness_correction = 1,
  };
  if (pp.substeps <= 0) {
    double k = ceil(p->dt / PBD_AUTO_SUBSTEP - 1e-9);
    pp.substeps = k < 1 ? 1 : (k > 1000 ? 1000 : (int)k);
  }
  if (pbd_create(&mp->s, mp->tm.nnodes, mp->tm.x, mp->tm.ntets, mp->tm.tets, &pp, &sub)) {
    verr_set(err, "%s", sub.msg);
    tet_mesh_free(&mp->tm);
    tet_embedding_free(&mp->emb);
    free(mp);
    return NULL;
  }
  if (cfg->fixed_below_set) pbd_fix_below(&mp->s, cfg->fixed_below);
  if (coupling_set_init(&mp->cpl, 256, 8192, err)) {
    pbd_model_destroy(&mp->base);
    return NULL;
  }
  mp->s.cpl = &mp->cpl;
  size_t ns = surf->nverts;
  mp->surf_x = malloc(3 * ns * sizeof(double));
  mp->surf_rest = malloc(3 * ns * sizeof(double));
  mp->surf_tris = malloc(3 * surf->ntris * sizeof(uint32_t));
  if (!mp->surf_x || !mp->surf_rest || !mp->surf_tris) {
    verr_set(err, "out of memory for the surface");
    pbd_model_destroy(&mp->base);
    return NULL;
  }
  memcpy(mp->surf_rest, surf->pos, 3 * ns * sizeof(double));
  memcpy(mp->surf_tris, surf->tris, 3 * surf->ntris * sizeof(uint32_t));
  /* Affine (barycentric) weights reproduce the rest surface exactly, up to
   * rounding, even for vertices embedded by extrapolation. */
  tet_embedding_apply(&mp->emb, &mp->tm, mp->s.x, mp->surf_x);

  model_t *m = &mp->base;
  m->ops = mode == PBD_MODE_PBD ? &PBD_OPS : &XPBD_OPS;
  m->error_kind = "volume_error";
  m->nnodes = mp->s.n;
  m->x = mp->s.x;
  m->v = mp->s.v;
  m->x_rest = mp->s.x_rest;
  m->ntets = mp->s.ntets;
  m->nsurf = ns;
  m->nsurf_tris = surf->ntris;
  m->surf_x = mp->surf_x;
  m->surf_rest = mp->surf_rest;
  m->surf_tris = mp->surf_tris;
  m->substeps = pp.substeps;
  m->stable_dt = INFINITY;
  m->implicit_tools = 1;
  return m;
}

pbd_t *model_pbd_solver(model_t *m) {
  if (!m || (m->ops != &PBD_OPS && m->ops != &XPBD_OPS)) return NULL;
  return &((model_pbd_t *)m)->s;
}

/* ---- topology edits (model.h edit, MODEL_EDIT_TETS) ------------------------ */

static void pbd_nodes(model_t *m, model_nodes_t *out) {
  model_pbd_t *mp = (model_pbd_t *)m;
  pbd_t *s = &mp->s;
  *out = (model_nodes_t){.n = s->n,
                         .cap = s->n,
                         .x = s->x,
                         .v = s->v,
                         .x_rest = s->x_rest,
                         .mass = s->mass,
                         .inv_mass = s->inv_mass,
                         .f_ext = s->f_ext,
                         .ntets = s->ntets,
                         .tets = s->tet,
                         .mass_total = s->p.mass};
}

/* The solver and the surface from the new mesh (see pbd.h). Everything new
 * is built first; the model changes only when all of it succeeded. */
static int pbd_commit(model_t *m, const model_topology_t *t, verr_t *err) {
  model_pbd_t *mp = (model_pbd_t *)m;
  pbd_t ns;
  verr_t sub;
  if (pbd_create(&ns, t->n, t->x_rest, t->ntets, t->tets, &mp->s.p, &sub))
    return verr_set(err, "rebuilding the solver after a cut: %s", sub.msg);
  size_t nt = t->ntris;
  uint32_t *tris = malloc((nt ? 3 * nt : 1) * sizeof *tris);
  uint32_t *map = malloc((t->n ? t->n : 1) * sizeof *map);
  if (!tris || !map) {
    free(tris);
    free(map);
    pbd_destroy(&ns);
    return verr_set(err, "out of memory for the surface after a cut");
  }
  size_t nv = 0;
  for (size_t i = 0; i < t->n; i++) map[i] = UINT32_MAX;
  for (size_t k = 0; k < 3 * nt; k++)
    if (map[t->tris[k]] == UINT32_MAX) map[t->tris[k]] = (uint32_t)nv++;
  uint32_t *node = malloc((nv ? nv : 1) * sizeof *node);
  double *sx = malloc((nv ? nv : 1) * 3 * sizeof(double)), *sr = malloc((nv ? nv : 1) * 3 * sizeof(double));
  double *sa = malloc((nv ? nv : 1) * 2 * sizeof(double));
  if (!node || !sx || !sr || !sa) {
    free(tris);
    free(map);
    free(node);
    free(sx);
    free(sr);
    free(sa);
    pbd_destroy(&ns);
    return verr_set(err, "out of memory for the surface after a cut");
  }
  for (size_t i = 0; i < t->n; i++)
    if (map[i] != UINT32_MAX) node[map[i]] = (uint32_t)i;
  for (size_t k = 0; k < 3 * nt; k++) tris[k] = map[t->tris[k]];
  free(map);
  memcpy(ns.x, t->x, 3 * t->n * sizeof(double));
  memcpy(ns.v, t->v, 3 * t->n * sizeof(double));
  for (size_t i = 0; i < t->n; i++)
    if (t->fixed[i]) pbd_fix_node(&ns, i);
  ns.rollbacks = mp->s.rollbacks;
  for (size_t v = 0; v < nv; v++) {
    memcpy(sx + 3 * v, t->x + 3 * (size_t)node[v], 3 * sizeof(double));
    memcpy(sr + 3 * v, t->x_rest + 3 * (size_t)node[v], 3 * sizeof(double));
    memcpy(sa + 2 * v, t->attr + 2 * (size_t)node[v], 2 * sizeof(double));
  }
  pbd_destroy(&mp->s);
  mp->s = ns;
  mp->s.cpl = &mp->cpl;
  free(mp->surf_x);
  free(mp->surf_rest);
  free(mp->surf_tris);
  free(mp->surf_node);
  free(mp->surf_attr);
  mp->surf_x = sx;
  mp->surf_rest = sr;
  mp->surf_tris = tris;
  mp->surf_node = node;
  mp->surf_attr = sa;
  m->nnodes = mp->s.n;
  m->x = mp->s.x;
  m->v = mp->s.v;
  m->x_rest = mp->s.x_rest;
  m->ntets = mp->s.ntets;
  m->nsurf = nv;
  m->nsurf_tris = nt;
  m->surf_x = sx;
  m->surf_rest = sr;
  m->surf_tris = tris;
  m->topology_version++;
  return 0;
}

static const model_edit_ops_t PBD_EDIT = {.kind = MODEL_EDIT_TETS, .nodes = pbd_nodes, .commit = pbd_commit};

const double *model_pbd_surface_attr(const model_t *m) {
  if (!m || (m->ops != &PBD_OPS && m->ops != &XPBD_OPS)) return NULL;
  return ((const model_pbd_t *)m)->surf_attr;
}
