/* SPDX-License-Identifier: Apache-2.0 */
/* model_adaptive: the "adaptive_mass_spring" scene model (docs/methods.md B ch. 5)
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

#include "physics/adaptive.h"
#include "state_blob.h"

/* Before every (fine) sub-step: the hook's tool springs of the last one
 * are gone; the hook declares this one's (am_add_coupling). */
static void am_pre(void *ctx) {
  model_t *m = ctx;
  coupling_set_clear(&((adaptive_model_t *)m)->cpl);
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
  coupling_set_free(&am->cpl);
  free(am);
}

static double am_energy(const model_t *m) { return adaptive_energy(&((const adaptive_model_t *)m)->ad); }

static double am_error(const model_t *m) { return adaptive_max_strain(&((const adaptive_model_t *)m)->ad); }

static void am_add_force(model_t *m, uint32_t i, const double f[3]) {
  adaptive_add_force(&((adaptive_model_t *)m)->ad, i, f);
}

/* Tool springs implicitly (physics/coupling.h, adaptive.h adaptive_step):
 * the stiffest tool is in none of the multi-rate bounds (coarse sub-steps,
 * fine ratio). Indices beyond the current mesh are left out. */
static void am_add_coupling(model_t *m, double k, size_t nw, const uint32_t *wi, const double *w, size_t nb,
                            const uint32_t *bi, const double *b) {
  adaptive_model_t *am = (adaptive_model_t *)m;
  if (!m->implicit_tools) return;
  coupling_add(&am->cpl, k, am->ad.n, nw, wi, w, nb, bi, b);
}

/* Checkpoints (model.h save/restore_topology). The refined mesh is a
 * function of the refinement centre alone (the coarse mesh never changes,
 * refinement reads rest areas, new rest positions are midpoints of coarse
 * rest positions), so the centre, the release timer and the version are
 * the whole topology: restoring refines the fresh model at that centre
 * again and then takes the saved positions and velocities. */
static int am_save_topology(const model_t *m, state_blob_t *b) {
  const adaptive_t *ad = &((const adaptive_model_t *)m)->ad;
  sb_put_u64(b, (uint64_t)ad->refined);
  sb_put_u64(b, ad->centre);
  sb_put_f64(b, ad->release_timer);
  sb_put_u64(b, ad->topology_version);
  return b->bad ? -1 : 0;
}

static int am_restore_topology(model_t *m, state_blob_t *b, size_t nnodes, const double *x, const double *v,
                               verr_t *err) {
  adaptive_model_t *am = (adaptive_model_t *)m;
  adaptive_t *ad = &am->ad;
  uint64_t refined = sb_get_u64(b), centre = sb_get_u64(b);
  double timer = sb_get_f64(b);
  uint64_t version = sb_get_u64(b);
  if (b->bad || refined > 1 || (refined && centre >= ad->n0) || !isfinite(timer) || timer < 0 || version == 0 ||
      version > UINT32_MAX)
    return verr_set(err, "refinement: bad centre, timer or version");
  if (ad->refined) adaptive_simplify(ad); /* a fresh model is coarse; be sure */
  /* A refinement that ran out of capacity leaves the coarse mesh, as it did
   * when saved: the node count decides. */
  if (refined) adaptive_refine(ad, (uint32_t)centre);
  if (ad->n != nnodes) {
    adaptive_simplify(ad);
    am_sync(am);
    m->topology_version = 0;
    ad->topology_version = 0;
    return verr_set(err, "refinement at vertex %llu gives %zu nodes, the checkpoint has %zu",
                    (unsigned long long)centre, ad->n, nnodes);
  }
  memcpy(ad->x, x, 3 * nnodes * sizeof(double));
  memcpy(ad->v, v, 3 * nnodes * sizeof(double));
  ad->release_timer = timer;
  ad->topology_version = (uint32_t)version;
  am_sync(am);
  return 0;
}

/* model.h surface_anchor / surface_locate: the coarse face of a triangle
 * outlives refinement and simplification, and adaptive_locate finds the
 * point's triangle inside it. */
static uint32_t am_surface_anchor(const model_t *m, uint32_t tri) {
  return adaptive_tri_face(&((const adaptive_model_t *)m)->ad, tri);
}

static uint32_t am_surface_locate(const model_t *m, uint32_t anchor, const double p[3], double bary[3]) {
  return adaptive_locate(&((const adaptive_model_t *)m)->ad, anchor, p, bary);
}

static const model_ops_t adaptive_ops = {
    .name = "adaptive_mass_spring",
    .step = am_step,
    .destroy = am_destroy,
    .energy = am_energy,
    .error_estimate = am_error,
    .add_surface_force = am_add_force,
    .add_surface_coupling = am_add_coupling,
    .save_topology = am_save_topology,
    .restore_topology = am_restore_topology,
    .surface_anchor = am_surface_anchor,
    .surface_locate = am_surface_locate,
};

model_t *model_adaptive_create(const model_params_t *p, verr_t *err) {
  const scene_organ_t *cfg = p->cfg;
  const scene_material_t *mat = &cfg->material;
  /* Seed 002 eq. 5.8-5.9 is semi-implicit (symplectic) Euler; the model
   * integrates itself, since its node count changes under the integrator. */
  if (cfg->integrator[0] && strcmp(cfg->integrator, "symplectic_euler") != 0) {
    verr_set(
        err,
        "adaptive_mass_spring integrates with symplectic Euler (docs/methods.md B eq. 5.8-5.9); integrator '%s' is "
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
                          /* Tool springs implicit (am_add_coupling): out of the bounds. */
                          .tool_stiffness = 0,
                          .mass_rule = ADAPT_MASS_AREA,
                          .k_rule = ADAPT_K_MEMBRANE};
  verr_t e;
  if (coupling_set_init(&am->cpl, 256, 8192, err)) {
    free(am);
    return NULL;
  }
  if (adaptive_create(&am->ad, p->surface, &ap, p->dt, cfg->solver.substeps, &e)) {
    coupling_set_free(&am->cpl);
    free(am);
    verr_set(err, "%s", e.msg);
    return NULL;
  }
  am->ad.cpl = &am->cpl;
  if (cfg->fixed_below_set) adaptive_fix_below(&am->ad, cfg->fixed_below);
  model_t *m = &am->base;
  m->ops = &adaptive_ops;
  m->implicit_tools = 1;
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
