/* SPDX-License-Identifier: Apache-2.0 */
/* model_vertex_based: the "vertex_based" scene model (docs/methods.md B ch. 4) behind
 * the common model interface. A surface model: nodes are the surface
 * vertices, surf_x == x. Gravity is not applied: the thesis model has none,
 * and the home springs hold the organ's rest shape (which is the shape under
 * gravity); applying it would make every vertex move every step and defeat
 * the constant-cost property. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "physics/model.h"
#include "physics/vertex_based.h"

typedef struct vb_model {
  model_t base;
  vb_t vb;
  uint32_t *tris; /* the render/contact triangles (base.surf_tris) */
} vb_model_t;

static void vbm_pre(void *ctx) {
  model_t *m = ctx;
  if (m->hook) m->hook(m, m->hook_ctx);
}

static int vbm_step(model_t *m, double h) {
  vb_model_t *vm = (vb_model_t *)m;
  if (vb_step(&vm->vb, h, m->substeps, vbm_pre, m) < 0) {
    m->rollbacks++;
    return -1;
  }
  return 0;
}

static void vbm_destroy(model_t *m) {
  vb_model_t *vm = (vb_model_t *)m;
  vb_destroy(&vm->vb);
  free(vm->tris);
  free(vm);
}

static double vbm_energy(const model_t *m) { return vb_energy(&((const vb_model_t *)m)->vb); }

static double vbm_error(const model_t *m) { return vb_max_edge_strain(&((const vb_model_t *)m)->vb); }

static void vbm_add_force(model_t *m, uint32_t i, const double f[3]) { vb_add_force(&((vb_model_t *)m)->vb, i, f); }

/* Tool springs implicitly (vertex_based.h vb_add_coupling): only the
 * stiffness matters to this model, the force itself came through
 * add_surface_force. */
static void vbm_add_coupling(model_t *m, double k, size_t nw, const uint32_t *wi, const double *w, size_t nb,
                             const uint32_t *bi, const double *b) {
  (void)nw, (void)wi, (void)w, (void)nb, (void)bi, (void)b;
  if (m->implicit_tools) vb_add_coupling(&((vb_model_t *)m)->vb, k);
}

static const model_ops_t vb_ops = {
    .name = "vertex_based",
    .step = vbm_step,
    .destroy = vbm_destroy,
    .energy = vbm_energy,
    .error_estimate = vbm_error,
    .add_surface_force = vbm_add_force,
    .add_surface_coupling = vbm_add_coupling,
};

model_t *model_vertex_based_create(const model_params_t *p, verr_t *err) {
  const scene_organ_t *cfg = p->cfg;
  const scene_material_t *mat = &cfg->material;
  vb_model_t *vm = calloc(1, sizeof *vm);
  if (!vm) {
    verr_set(err, "out of memory");
    return NULL;
  }
  vb_params_t vp = {.mass = mat->mass,
                    .home_stiffness = mat->home_stiffness,
                    .home_damping = mat->home_damping,
                    .slope = {mat->slope_m1, mat->slope_m2, mat->slope_m3},
                    .tool_stiffness = 0}; /* every tool spring is declared: implicit (issue 17.1) */
  verr_t e;
  if (vb_create(&vm->vb, p->surface, &vp, &e)) {
    free(vm);
    verr_set(err, "%s", e.msg);
    return NULL;
  }
  if (cfg->fixed_below_set) vb_fix_below(&vm->vb, cfg->fixed_below);
  model_t *m = &vm->base;
  m->ops = &vb_ops;
  m->implicit_tools = 1;
  m->error_kind = "max_edge_strain";
  m->nnodes = m->nsurf = vm->vb.n;
  m->x = m->surf_x = vm->vb.x;
  m->v = vm->vb.v;
  m->x_rest = m->surf_rest = vm->vb.x_rest;
  m->ntets = 0;
  m->nsurf_tris = p->surface->ntris;
  /* The model keeps no triangles of its own (rings are all it needs), so
   * the surface's triangles are copied for the render/contact surface. */
  uint32_t *tris = malloc(3 * p->surface->ntris * sizeof(uint32_t));
  if (!tris) {
    vb_destroy(&vm->vb);
    free(vm);
    verr_set(err, "out of memory");
    return NULL;
  }
  memcpy(tris, p->surface->tris, 3 * p->surface->ntris * sizeof(uint32_t));
  vm->tris = tris;
  m->surf_tris = tris;
  m->stable_dt = vb_stable_dt(&vm->vb);
  if (cfg->solver.substeps > 0) {
    m->substeps = cfg->solver.substeps;
  } else {
    double safe = 0.9 * m->stable_dt, need = isfinite(safe) ? ceil(p->dt / safe) : 1;
    if (!(need <= 256)) {
      verr_set(err,
               "vertex_based with this tool stiffness is stable only below dt = %.3g s, %.0f sub-steps of "
               "%.3g s (limit 256); raise mass or home_stiffness, or lower slope_m1 or the tool stiffness",
               m->stable_dt, need, p->dt);
      vbm_destroy(m);
      return NULL;
    }
    m->substeps = need < 1 ? 1 : (int)need;
  }
  return m;
}

vb_t *model_vertex_based_state(model_t *m) { return m && m->ops == &vb_ops ? &((vb_model_t *)m)->vb : NULL; }
