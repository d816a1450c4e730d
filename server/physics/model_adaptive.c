/* model_adaptive: the "adaptive_mass_spring" scene model (seed 002 ch. 5)
 * behind the common model interface. A surface model (surf_x == x) whose
 * surface changes: after a step that refined or simplified, nnodes, nsurf,
 * nsurf_tris and substeps are updated and then model_t.topology_version
 * (model.h's contract) takes the adaptive core's counter, so it moves by one
 * per refinement or simplification (by two when a moving contact re-centres:
 * simplify, then refine). The arrays behind x, v, surf_x, surf_rest and
 * surf_tris are allocated at their maximum size at create, so their
 * addresses never change (the contract allows it; this model does not). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "adaptive.h"

static void am_pre(void *ctx) {
  model_t *m = ctx;
  if (m->hook) m->hook(m, m->hook_ctx);
}

static void am_sync(adaptive_model_t *am) {
  const adaptive_t *ad = &am->ad;
  model_t *m = &am->base;
  m->nnodes = m->nsurf = ad->n;
  m->nsurf_tris = ad->nt;
  m->substeps = ad->substeps;
  /* The bound the sub-steps follow: eq. 5.18 divides the coarse one as the
   * sub-step count grows. */
  m->stable_dt = ad->stable_dt0 * (double)ad->substeps0 / (double)ad->substeps;
  /* Last: the counts above are what the new version describes. */
  m->topology_version = ad->topology_version;
}

static int am_step(model_t *m, double h) {
  adaptive_model_t *am = (adaptive_model_t *)m;
  int r = adaptive_step(&am->ad, h, am_pre, m);
  if (r < 0) m->rollbacks++;
  am_sync(am);
  return r;
}

static void am_destroy(model_t *m) {
  adaptive_model_t *am = (adaptive_model_t *)m;
  adaptive_destroy(&am->ad);
  free(am);
}

static double am_energy(const model_t *m) { return adaptive_energy(&((const adaptive_model_t *)m)->ad); }

static double am_error(const model_t *m) { return adaptive_max_strain(&((const adaptive_model_t *)m)->ad); }

static void am_add_force(model_t *m, uint32_t i, const double f[3]) {
  adaptive_add_force(&((adaptive_model_t *)m)->ad, i, f);
}

static const model_ops_t adaptive_ops = {
    .name = "adaptive_mass_spring",
    .step = am_step,
    .destroy = am_destroy,
    .energy = am_energy,
    .error_estimate = am_error,
    .add_surface_force = am_add_force,
};

model_t *model_adaptive_create(const model_params_t *p, verr_t *err) {
  const scene_organ_t *cfg = p->cfg;
  const scene_material_t *mat = &cfg->material;
  /* Seed 002 eq. 5.8-5.9 is semi-implicit (symplectic) Euler; the model
   * integrates itself, since its node count changes under the integrator. */
  if (cfg->integrator[0] && strcmp(cfg->integrator, "symplectic_euler") != 0) {
    verr_set(err,
             "adaptive_mass_spring integrates with symplectic Euler (seed 002 eq. 5.8-5.9); integrator '%s' is "
             "not available for it",
             cfg->integrator);
    return NULL;
  }
  adaptive_model_t *am = calloc(1, sizeof *am);
  if (!am) {
    verr_set(err, "out of memory");
    return NULL;
  }
  adaptive_params_t ap = {.mass = mat->mass,
                          .stiffness = mat->stiffness,
                          .damping = mat->damping,
                          .home_stiffness = mat->home_stiffness,
                          .home_damping = mat->home_damping,
                          .gravity = {p->gravity[0], p->gravity[1], p->gravity[2]},
                          .refine_area = mat->refine_area,
                          .refine_levels = mat->refine_levels,
                          .refine_force = ADAPT_DEFAULT_REFINE_FORCE,
                          .release_time = ADAPT_DEFAULT_RELEASE_TIME,
                          .tool_stiffness = p->tool_stiffness,
                          .mass_rule = ADAPT_MASS_AREA,
                          .k_rule = ADAPT_K_MEMBRANE};
  verr_t e;
  if (adaptive_create(&am->ad, p->surface, &ap, p->dt, cfg->solver.substeps, &e)) {
    free(am);
    verr_set(err, "%s", e.msg);
    return NULL;
  }
  if (cfg->fixed_below_set) adaptive_fix_below(&am->ad, cfg->fixed_below);
  model_t *m = &am->base;
  m->ops = &adaptive_ops;
  m->error_kind = "max_edge_strain";
  m->x = m->surf_x = am->ad.x;
  m->v = am->ad.v;
  m->x_rest = m->surf_rest = am->ad.x_rest;
  m->surf_tris = am->ad.tris;
  m->ntets = 0;
  am_sync(am);
  return m;
}

adaptive_model_t *model_adaptive_of(model_t *m) { return m && m->ops == &adaptive_ops ? (adaptive_model_t *)m : NULL; }
