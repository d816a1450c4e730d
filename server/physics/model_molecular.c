/* SPDX-License-Identifier: Apache-2.0 */
/* model_molecular: the molecular force system (molecular.h, docs/methods.md A eq.
 * 6-11) as model_t for the scene model name "molecular", stepped by the
 * scene's integrator (integrator.h).
 *
 * Parameters: the set is refused at load unless bond_k angle_k > 2
 * stretch_bend_k^2 (molecular_check_params; docs/numerics.md case 13). The
 * material's `damping` is the bonds' Kelvin-Voigt damping, as on the
 * mass-spring edges.
 *
 * Sub-steps: solver.substeps when given; otherwise 1 for implicit Euler and
 * for the explicit schemes the fewest that keep each sub-step within 0.9 x
 * the stable dt, more than 256 refused with the figures. The stable dt is
 * integrator_stable_dt of the largest eigenvalues of M^-1 K and M^-1 C at
 * rest (power iteration, the stiffest tool spring added to every vertex as a
 * home spring), and of the slowest mode (home springs alone), which decides
 * explicit Euler's damped bound when the ground damping ratio is the lower.
 * On organs the angle term usually sets omega_max: its stiffness is about
 * k_theta sin^2(theta0) / l^2 per corner, which at the default 1e-3 J on
 * 1.2 mm edges is 20 x the 30 N/m bonds.
 *
 * Implicit Euler gets the Gauss-Newton K (definite_jacobian) for its
 * conjugate gradients, as the mass-spring model does.
 *
 * Live error figure: error_kind "max_edge_strain", the largest |r/r0 - 1|
 * over bonds. "energy_drift" would need a conservative run, but a live organ
 * is damped (ground and bond damping), held by home springs and pushed by
 * tools, so its energy changes for physical reasons; bond strain means the
 * same thing in every run and matches the mass-spring surface model.
 *
 * External forces: add_surface_force adds to the vertex's force for the
 * current sub-step; f_ext is cleared after every sub-step, so the hook
 * (called by the integrator before each sub-step) sets that sub-step's
 * contact forces and a force added outside a step acts on the next
 * sub-step only.
 *
 * Rollback (physics/model_guard.h): a step starts by saving the state if
 * it is finite; a step that ends non-finite restores the saved state (the
 * last finite one) and returns -1. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "physics/coupling.h"
#include "physics/integrator.h"
#include "physics/model.h"
#include "physics/model_guard.h"
#include "physics/molecular.h"

model_t *model_molecular_create(const model_params_t *p, verr_t *err);

typedef struct mol_model {
  model_t m; /* first: the model_t the caller holds */
  molecular_t mol;
  integrator_t it;
  model_guard_t guard; /* the last finite state */
  coupling_set_t cpl;  /* symplectic Euler, implicit_pcg: the sub-step's tool springs (implicit) */
} mol_model_t;

/* implicit_pcg: the right-hand side in one fused pass (molecular_linear_rhs).
 * diag stays 0 (a mass-only Jacobi preconditioner, as without linearize:
 * the stiffness diagonal cost a pass of its own and saved under 10 % of
 * the iterations on the gallbladder) and products go through
 * stiffness_mul (linear_mul NULL: a cached Jacobian was slower, its 1.3 MB
 * per gallbladder outgrew the cache that the recomputing kernel fits in). */
static void mm_linearize(force_system_t *s, double h, double *rhs, double *diag) {
  molecular_linear_rhs(s->ctx, h, rhs);
  memset(diag, 0, 3 * s->n * sizeof(double));
}

/* Between kick and drift: the declared tool springs implicitly
 * (physics/coupling.h), as in the mass-spring models. */
static void mm_correct_v(force_system_t *s, double h) {
  molecular_t *mol = s->ctx;
  mol_model_t *mm = (mol_model_t *)mol->user;
  coupling_set_apply(&mm->cpl, mol->inv_mass, h, mol->v);
}

/* Integrators call this before every force evaluation (twice per Verlet
 * sub-step, four times per RK4 one), so external forces are set afresh each
 * time, never accumulated. */
static void mm_pre_substep(force_system_t *s) {
  molecular_t *mol = s->ctx;
  model_t *m = mol->user;
  memset(mol->f_ext, 0, 3 * mol->n * sizeof(double));
  mol_model_t *mm = (mol_model_t *)m;
  coupling_set_clear(&mm->cpl);
  if (m->hook) m->hook(m, m->hook_ctx);
  /* Without a tool spring the integrator keeps its fused loop. */
  if (m->implicit_tools) s->correct_v = mm->cpl.n ? mm_correct_v : NULL;
}

static int mm_step(model_t *m, double h) {
  mol_model_t *mm = (mol_model_t *)m;
  molecular_t *mol = &mm->mol;
  size_t bytes = 3 * mol->n * sizeof(double);
  model_guard_save_finite(&mm->guard, mol->x, mol->v, mol->n, NULL);
  int sub = m->substeps < 1 ? 1 : m->substeps;
  double hs = h / sub;
  for (int s = 0; s < sub; s++) {
    integrator_substep(&mm->it, &mol->fs, hs); /* calls the hook first */
    memset(mol->f_ext, 0, bytes);              /* contact forces hold for one sub-step (model.h) */
  }
  return model_guard_check(&mm->guard, mol->x, mol->v, mol->n, NULL, &m->rollbacks);
}

static void mm_destroy(model_t *m) {
  mol_model_t *mm = (mol_model_t *)m;
  integrator_destroy(&mm->it);
  molecular_destroy(&mm->mol);
  model_guard_free(&mm->guard);
  coupling_set_free(&mm->cpl);
  free(mm);
}

static double mm_energy(const model_t *m) { return molecular_energy(&((const mol_model_t *)m)->mol); }

static double mm_error(const model_t *m) { return molecular_max_strain(&((const mol_model_t *)m)->mol); }

static void mm_add_surface_force(model_t *m, uint32_t i, const double f[3]) {
  molecular_t *mol = &((mol_model_t *)m)->mol;
  if (i >= mol->n) return;
  for (int k = 0; k < 3; k++) mol->f_ext[3 * (size_t)i + k] += f[k];
}

/* A tool spring (model.h): the surface is the node set. */
static void mm_add_surface_coupling(model_t *m, double k, size_t nw, const uint32_t *wi, const double *w, size_t nb,
                                    const uint32_t *bi, const double *b) {
  mol_model_t *mm = (mol_model_t *)m;
  if (!m->implicit_tools) return;
  coupling_add(&mm->cpl, k, mm->mol.n, nw, wi, w, nb, bi, b);
}

static const model_ops_t MOL_OPS = {
    .name = "molecular",
    .step = mm_step,
    .destroy = mm_destroy,
    .energy = mm_energy,
    .error_estimate = mm_error,
    .add_surface_force = mm_add_surface_force,
    .add_surface_coupling = mm_add_surface_coupling,
};

/* Stable dt and sub-steps (file comment). */
static int choose_substeps(mol_model_t *mm, const model_params_t *p, integrator_kind_t kind, verr_t *err) {
  const scene_organ_t *cfg = p->cfg;
  const molecular_t *mol = &mm->mol;
  double lk, lc;
  /* Tool springs taken implicitly (coupling.h) stay out of the bound. */
  double tool = mm->m.implicit_tools ? 0 : p->tool_stiffness;
  if (molecular_rest_lambdas(mol, tool, &lk, &lc)) return verr_set(err, "out of memory");
  double m_node = mol->p.mass / (double)mol->n;
  double lk0 = (mol->p.home_stiffness + tool) / m_node, lc0 = mol->p.home_damping / m_node;
  return integrator_choose_substeps(kind, p->dt, cfg->solver.substeps, lk, lc, lk0, lc0,
                                    "lower angle_k, bond_k, stretch_bend_k, damping or tool stiffness, raise the "
                                    "mass, or use implicit_euler (explicit_euler needs damping)",
                                    &mm->m.substeps, &mm->m.stable_dt, err);
}

model_t *model_molecular_create(const model_params_t *p, verr_t *err) {
  const scene_organ_t *cfg = p->cfg;
  const scene_material_t *mat = &cfg->material;
  /* docs/numerics.md case 13: a non-positive-definite set is refused at load. */
  if (molecular_check_params(mat->bond_k, mat->angle_k, mat->stretch_bend_k, err)) return NULL;
  int kind = integrator_parse(cfg->integrator);
  if (kind < 0) {
    verr_set(err, "integrator '%s' is not known", cfg->integrator);
    return NULL;
  }
  if (!(p->dt > 0) || !isfinite(p->dt) || !(p->tool_stiffness >= 0)) {
    verr_set(err, "molecular model: dt must be > 0 and tool stiffness >= 0 (got %g, %g)", p->dt, p->tool_stiffness);
    return NULL;
  }
  mol_model_t *mm = calloc(1, sizeof *mm);
  if (!mm) {
    verr_set(err, "out of memory");
    return NULL;
  }
  mol_params_t mp = {.mass = mat->mass,
                     .bond_k = mat->bond_k,
                     .angle_k = mat->angle_k,
                     .stretch_bend_k = mat->stretch_bend_k,
                     .bond_damping = mat->damping,
                     .home_stiffness = mat->home_stiffness,
                     .home_damping = mat->home_damping,
                     .gravity = {p->gravity[0], p->gravity[1], p->gravity[2]}};
  molecular_t *mol = &mm->mol;
  if (molecular_create(mol, p->surface, &mp, err)) {
    free(mm);
    return NULL;
  }
  mol->user = &mm->m;
  mol->fs.pre_substep = mm_pre_substep;
  mol->definite_jacobian = kind == INT_IMPLICIT_EULER || kind == INT_IMPLICIT_PCG;
  /* Symplectic Euler and implicit_pcg take the tool springs implicitly
   * (issue 17.1): the sub-steps then follow the tissue alone. */
  if (kind == INT_SYMPLECTIC_EULER || kind == INT_IMPLICIT_PCG) {
    mm->m.implicit_tools = 1;
    if (coupling_set_init(&mm->cpl, 256, 8192, err)) {
      mm_destroy(&mm->m);
      return NULL;
    }
  }
  if (kind == INT_IMPLICIT_PCG) mol->fs.linearize = mm_linearize;
  if (cfg->fixed_below_set) molecular_fix_below(mol, cfg->fixed_below);
  size_t n = mol->n;
  if (model_guard_reserve(&mm->guard, n)) {
    verr_set(err, "out of memory for %zu vertices", n);
    mm_destroy(&mm->m);
    return NULL;
  }
  model_guard_save(&mm->guard, mol->x, mol->v, n, NULL);

  model_t *m = &mm->m;
  m->ops = &MOL_OPS;
  m->error_kind = "max_edge_strain";
  m->nnodes = n;
  m->x = mol->x;
  m->v = mol->v;
  m->x_rest = mol->x_rest;
  m->ntets = 0;
  m->nsurf = n; /* a surface model: the surface is the node set */
  m->nsurf_tris = mol->ntris;
  m->surf_x = mol->x;
  m->surf_rest = mol->x_rest;
  m->surf_tris = mol->tri_idx;
  if (choose_substeps(mm, p, (integrator_kind_t)kind, err) ||
      integrator_init(&mm->it, (integrator_kind_t)kind, n, cfg->solver.cg_tolerance, cfg->solver.cg_max_iterations,
                      err)) {
    mm_destroy(m);
    return NULL;
  }
  return m;
}
