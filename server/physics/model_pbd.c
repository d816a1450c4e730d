/* model_pbd: the scene models "pbd" and "xpbd" behind model_t. The organ's
 * surface is filled with tetrahedra (tet_mesh_build), the solver in pbd.c
 * runs on their nodes, and the render/contact surface rides along through
 * its barycentric embedding. Messages do not name the organ: model_create
 * (model_registry.c) prefixes it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cutting/tet_cut.h"
#include "physics/pbd.h"
#include "state_blob.h"
#include "tet_mesh.h"

typedef struct model_pbd {
  model_t base; /* first, so model_t * and model_pbd_t * convert */
  pbd_t s;
  tet_mesh_t tm;
  tet_embedding_t emb;
  double *surf_x, *surf_rest;
  uint32_t *surf_tris;
  /* Cutting: NULL until enabled or a cut starts. After the first split the
   * surface is the tetrahedral boundary: surf_node maps its vertices to
   * nodes (and replaces the embedding), surf_attr holds their attribute. */
  tet_cut_t *cut;
  uint32_t *surf_node;
  double *surf_attr;
  int cut_broken; /* a rebuild failed: the solver no longer matches the cutter */
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
  if (mp->cut) tet_cut_destroy(mp->cut);
  free(mp->cut);
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

static int pbd_save_topology(const model_t *m, state_blob_t *b);
static int pbd_restore_topology(model_t *m, state_blob_t *b, size_t nnodes, const double *x, const double *v,
                                verr_t *err);

/* pbd and xpbd share every operation; only the name (and the mode the
 * model was created with) differ. */
#define PBD_FAMILY_OPS(model_name)                                                                                     \
  {                                                                                                                    \
    .name = model_name, .step = pbd_model_step, .destroy = pbd_model_destroy, .energy = pbd_model_energy,              \
    .error_estimate = pbd_model_error, .add_surface_force = pbd_model_add_surface_force,                               \
    .save_topology = pbd_save_topology, .restore_topology = pbd_restore_topology                                       \
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
  tet_build_report_t rep;
  if (tet_mesh_build(surf, cfg->solver.tet_size, &mp->tm, &mp->emb, &rep, &sub)) {
    verr_set(err, "cannot build a tetrahedral mesh: %s", sub.msg);
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
  return m;
}

pbd_t *model_pbd_solver(model_t *m) {
  if (!m || (m->ops != &PBD_OPS && m->ops != &XPBD_OPS)) return NULL;
  return &((model_pbd_t *)m)->s;
}

/* ---- cutting ---------------------------------------------------------------- */

int model_pbd_enable_cutting(model_t *m, verr_t *err) {
  pbd_t *s = model_pbd_solver(m);
  if (!s) return verr_set(err, "cutting needs a pbd or xpbd model");
  model_pbd_t *mp = (model_pbd_t *)m;
  if (mp->cut) return 0;
  uint8_t *fixed = malloc(s->n);
  mp->cut = calloc(1, sizeof *mp->cut);
  if (!fixed || !mp->cut) {
    free(fixed);
    free(mp->cut);
    mp->cut = NULL;
    return verr_set(err, "out of memory for the cutter");
  }
  for (size_t i = 0; i < s->n; i++) fixed[i] = s->inv_mass[i] == 0;
  int rc = tet_cut_create(mp->cut, s->n, s->x_rest, s->x, s->v, fixed, s->ntets, s->tet, err);
  free(fixed);
  if (rc) {
    free(mp->cut);
    mp->cut = NULL;
    return -1;
  }
  return 0;
}

/* The solver and the surface from the cutter's mesh (see pbd.h). Everything
 * new is built first; the model changes only when all of it succeeded. */
static int rebuild(model_pbd_t *mp, verr_t *err) {
  tet_cut_t *c = mp->cut;
  model_t *m = &mp->base;
  pbd_t ns;
  verr_t sub;
  if (pbd_create(&ns, c->n, c->x_rest, c->ntets, c->tet, &mp->s.p, &sub)) {
    mp->cut_broken = 1;
    return verr_set(err, "rebuilding the solver after a cut: %s", sub.msg);
  }
  uint32_t *tris = NULL;
  size_t nt = tet_cut_boundary(c, &tris);
  uint32_t *map = malloc(c->n * sizeof *map);
  if (nt == (size_t)-1 || !map) {
    free(tris);
    free(map);
    pbd_destroy(&ns);
    mp->cut_broken = 1;
    return verr_set(err, "out of memory for the surface after a cut");
  }
  size_t nv = 0;
  for (size_t i = 0; i < c->n; i++) map[i] = UINT32_MAX;
  for (size_t k = 0; k < 3 * nt; k++)
    if (map[tris[k]] == UINT32_MAX) map[tris[k]] = (uint32_t)nv++;
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
    mp->cut_broken = 1;
    return verr_set(err, "out of memory for the surface after a cut");
  }
  for (size_t i = 0; i < c->n; i++)
    if (map[i] != UINT32_MAX) node[map[i]] = (uint32_t)i;
  for (size_t k = 0; k < 3 * nt; k++) tris[k] = map[tris[k]];
  free(map);
  memcpy(ns.x, c->x, 3 * c->n * sizeof(double));
  memcpy(ns.v, c->v, 3 * c->n * sizeof(double));
  for (size_t i = 0; i < c->n; i++)
    if (c->fixed[i]) pbd_fix_node(&ns, i);
  ns.rollbacks = mp->s.rollbacks;
  for (size_t v = 0; v < nv; v++) {
    memcpy(sx + 3 * v, c->x + 3 * (size_t)node[v], 3 * sizeof(double));
    memcpy(sr + 3 * v, c->x_rest + 3 * (size_t)node[v], 3 * sizeof(double));
    memcpy(sa + 2 * v, c->attr + 2 * (size_t)node[v], 2 * sizeof(double));
  }
  pbd_destroy(&mp->s);
  mp->s = ns;
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

/* Runs one cutter call on the solver's current state. */
static int cut_call(model_t *m, const double *tip, const double *handle, verr_t *err) {
  if (!model_pbd_solver(m)) return verr_set(err, "cutting needs a pbd or xpbd model");
  model_pbd_t *mp = (model_pbd_t *)m;
  if (mp->cut_broken) return verr_set(err, "cutting disabled after a failed rebuild");
  if (!tip && !mp->cut) return 0; /* nothing was cut: nothing to end */
  if (!mp->cut && model_pbd_enable_cutting(m, err)) return -1;
  tet_cut_t *c = mp->cut;
  /* The cutter holds the same nodes as the solver (rebuilt together). */
  memcpy(c->x, mp->s.x, 3 * c->n * sizeof(double));
  memcpy(c->v, mp->s.v, 3 * c->n * sizeof(double));
  uint32_t version = c->version;
  int n = tip ? tet_cut_advance(c, tip, handle, err) : tet_cut_end(c, err);
  if (n < 0) return -1;
  if (c->version != version && rebuild(mp, err)) return -1;
  return n;
}

int model_pbd_cut(model_t *m, const double tip[3], const double handle[3], verr_t *err) {
  if (!tip || !handle) return verr_set(err, "no blade");
  return cut_call(m, tip, handle, err);
}

int model_pbd_cut_end(model_t *m, verr_t *err) { return cut_call(m, NULL, NULL, err); }

const struct tet_cut *model_pbd_cutter(const model_t *m) {
  if (!m || (m->ops != &PBD_OPS && m->ops != &XPBD_OPS)) return NULL;
  return ((const model_pbd_t *)m)->cut;
}

const double *model_pbd_surface_attr(const model_t *m) {
  if (!m || (m->ops != &PBD_OPS && m->ops != &XPBD_OPS)) return NULL;
  return ((const model_pbd_t *)m)->surf_attr;
}

/* ---- checkpoints (model.h save/restore_topology) ---------------------------- */

/* A cut model is its cutter's mesh: the solver and the surface are rebuilt
 * from it exactly as after the last cut (rebuild above), so saving the
 * cutter (tet_cut_save) and the topology version is enough. */
static int pbd_save_topology(const model_t *m, state_blob_t *b) {
  const model_pbd_t *mp = (const model_pbd_t *)m;
  if (!mp->cut || mp->cut_broken) return -1;
  tet_cut_save(mp->cut, b);
  sb_put_u64(b, m->topology_version);
  return b->bad ? -1 : 0;
}

static int pbd_restore_topology(model_t *m, state_blob_t *b, size_t nnodes, const double *x, const double *v,
                                verr_t *err) {
  model_pbd_t *mp = (model_pbd_t *)m;
  tet_cut_t *nc = calloc(1, sizeof *nc);
  if (!nc) return verr_set(err, "out of memory for the cutter");
  verr_t sub;
  if (tet_cut_load(nc, b, &sub)) {
    free(nc);
    return verr_set(err, "cut mesh: %s", sub.msg);
  }
  uint64_t version = sb_get_u64(b);
  if (b->bad || version == 0 || version > UINT32_MAX || nc->n != nnodes) {
    tet_cut_destroy(nc);
    free(nc);
    return verr_set(err, "cut mesh: bad topology version or node count");
  }
  tet_cut_t *old = mp->cut;
  mp->cut = nc;
  if (rebuild(mp, err)) { /* the model is unchanged: back to the old cutter */
    mp->cut = old;
    mp->cut_broken = 0;
    tet_cut_destroy(nc);
    free(nc);
    return -1;
  }
  if (old) tet_cut_destroy(old);
  free(old);
  m->topology_version = (uint32_t)version;
  memcpy(mp->s.x, x, 3 * m->nnodes * sizeof(double));
  memcpy(mp->s.v, v, 3 * m->nnodes * sizeof(double));
  memcpy(nc->x, x, 3 * m->nnodes * sizeof(double));
  memcpy(nc->v, v, 3 * m->nnodes * sizeof(double));
  surface_from_nodes(mp, mp->s.x);
  return 0;
}
