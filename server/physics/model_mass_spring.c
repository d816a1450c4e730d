/* SPDX-License-Identifier: Apache-2.0 */
/* model_mass_spring: the mass-spring force systems of mass_spring.h as
 * model_t, stepped by an integrator from integrator.h.
 *
 *   mass_spring_surface  springs on the surface mesh's edges; the surface IS
 *                        the node set; no tetrahedra are built.
 *                        error_kind "max_edge_strain": max |L/L0 - 1|.
 *   mass_spring_tet      springs on the edges of a tetrahedral mesh built
 *                        from the surface (tet_mesh_build, solver.tet_size);
 *                        the surface is embedded barycentrically and follows
 *                        the nodes. error_kind "volume_error": |V/V0 - 1| of
 *                        the whole tetrahedral volume.
 *
 * Sub-steps: solver.substeps when given; otherwise 1 for implicit Euler
 * (unconditionally stable) and for the explicit schemes the fewest that keep
 * each sub-step below 0.9 x the stable dt. The stable dt comes from the
 * largest eigenvalues of M^-1 K and M^-1 C at rest (power iteration, with
 * the stiffest tool spring added to every node as a home spring) through
 * integrator_stable_dt, and also from the slowest mode (the home springs
 * alone): that one decides explicit Euler's damped bound c/omega^2 when the
 * home damping ratio is lower than the edges'. More than 256 sub-steps are
 * refused with the figures.
 *
 * Symplectic Euler (the live default) keeps two things out of that bound
 * (issue 17). The tool springs: they are integrated implicitly
 * (physics/coupling.h, declared by the runtime through
 * add_surface_coupling), so the stiffest tool is not added to the nodes.
 * And the edge dampers' rate in the stiffest modes: on fine meshes the
 * Kelvin-Voigt dampers (lambda_c of M^-1 C, large because the nodes are
 * light) made most of the bound (gallbladder: 4 of its 1 ms step's
 * sub-steps instead of 2). With the sub-step h, the damper force is
 * scaled by s = min(1, MS_DAMPING_CAP / (h lambda_c)) (damping_scale,
 * mass_spring.h) for the fewest sub-steps that are stable with
 * lambda_c s: modes slower than lambda_c s keep their physical damping,
 * the stiffest ones lose at most half their velocity per sub-step instead
 * of more (they are not resolved at that h either way). Requested
 * sub-steps (solver.substeps) keep the full damping.
 *
 * Regional sleeping (physics/ms_regions.h, issue 17): under symplectic Euler
 * a surface organ integrates only its awake nodes (solver.region_force > 0,
 * the default); the tool forces and springs the hook adds wake the nodes
 * they act on, f_ext is cleared over the nodes it was set on, and the step
 * is guarded over the nodes it may change (ms_regions_begin_step), unless
 * the sleeping nodes were derived again for this step (built: after a
 * topology change, a rollback, a change of material or a write from
 * outside), when the whole state is guarded as before.
 *
 * implicit_pcg (integrator.h, issue 17.3) is one step per scene step: the
 * tool springs implicit as under symplectic Euler (correct_v after the
 * solve), the spring pass fused with the Jacobian (physics/ms_linear.h),
 * no energy guard (docs/numerics.md §10).
 *
 * Implicit Euler is one linearised step (integrator.h), which is blind to
 * what the linearisation misses: a flat cloth let go under gravity has no
 * out-of-plane stiffness at rest, so one 33 ms step moves its nodes straight
 * down and stretches the springs far beyond what they would reach, creating
 * energy that then has to be damped out again. Each implicit sub-step is
 * therefore energy-guarded (the step-size control of Baraff & Witkin 1998,
 * with energy as the test): it is accepted if the total energy did not grow
 * by more than the external forces' work (f_ext . dx, exact for forces
 * constant over the sub-step) plus 0.1 % of the kinetic and elastic energy
 * (room for the CG tolerance); otherwise it is undone and retried at half
 * the size, down to 1/256 of the sub-step, after which it is taken as is.
 * After an accepted attempt the size doubles again up to the full sub-step.
 *
 * Rollback (physics/model_guard.h): each step starts by saving the state
 * if it is finite; a step that ends non-finite restores the saved state and
 * returns -1. That is the state before the call, or, if something outside
 * wrote a non-finite value into the state since the last step, the state
 * before that step: the last one known finite (saving every step's end as
 * well would cost a second copy of the state per step for a case that
 * should not happen). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "physics/coupling.h"
#include "physics/integrator.h"
#include "physics/mass_spring.h"
#include "physics/model.h"
#include "physics/model_guard.h"
#include "physics/model_mass_spring.h"
#include "physics/model_volume.h"
#include "physics/ms_linear.h"
#include "physics/ms_regions.h"
#include "state_blob.h"
#include "tet_mesh.h"
#include "vmath.h"

/* h lambda_c at most this in the stiffest modes (file comment). */
#define MS_DAMPING_CAP 0.5

typedef struct ms_model {
  model_t m; /* first: the model_t the caller holds */
  mass_spring_t ms;
  integrator_t it;
  int tet;
  tet_mesh_t tm;                    /* tet variant */
  tet_embedding_t emb;              /* tet variant */
  double volume0;                   /* tet variant: rest volume, m^3 */
  model_guard_t guard;              /* the last finite state */
  double *surf_buf, *surf_rest_buf; /* tet variant: 3 nsurf */
  uint32_t *tris;                   /* 3 nsurf_tris, the model's own copy */
  double *try_x, *try_v;            /* implicit Euler: 3 nnodes, the state before an attempt */
  /* What choose_substeps needs again after a topology change (cutting). */
  double dt, tool_stiffness;
  int requested_substeps;
  size_t tri_cap; /* capacity of tris */
  /* Cutting only (ms_prepare): the dominant vector of M^-1 K
   * at rest and a scratch vector (3 cap each, NULL otherwise), the bound the
   * sub-steps follow, and the state of a re-estimate spread over steps. */
  double *eig_k, *eig_y;
  double lam_k;
  int refining, refine_count;
  double refine_lambda;
  coupling_set_t cpl; /* symplectic Euler, implicit_pcg: the tool springs of the sub-step (implicit) */
  ms_linear_t lin;    /* implicit_pcg: the step's Jacobian blocks */
  /* Regional sleeping (physics/ms_regions.h): surface model under
   * symplectic Euler with solver.region_force > 0. The nodes given an
   * external force since the last clear (f_ext is cleared there only, not
   * over every node; ntouched > n: clear all), and the material the
   * regions were decided under (a change wakes every node). */
  int regions;
  ms_regions_t reg;
  uint32_t *touched;
  size_t ntouched;
  ms_params_t reg_p;
  double reg_damping_scale;
  const double *reg_k_scale;
  /* model.h outside_writes as of the end of the last step: another value
   * at the next step means a write from outside since. */
  uint64_t seen_writes;
  /* The last step was guarded by the regions (its guard lists every node
   * it may have moved: last_step_moved). */
  int moved_listed;
} ms_model_t;

static void embed(ms_model_t *mm) {
  if (mm->tet) tet_embedding_apply(&mm->emb, &mm->tm, mm->ms.x, mm->surf_buf);
}

/* Symplectic Euler, between kick and drift: the declared tool springs
 * implicitly (physics/coupling.h). */
static void correct_v(force_system_t *s, double h) {
  ms_model_t *mm = s->ctx;
  coupling_set_apply(&mm->cpl, mm->ms.inv_mass, h, mm->ms.v);
}

/* implicit_pcg: the fused force and Jacobian pass (physics/ms_linear.h).
 * The cache holds every spring: ms_commit_nodes reserves it before a cut
 * changes the springs. */
static void linearize(force_system_t *s, double h, double *rhs, double *diag) {
  ms_model_t *mm = s->ctx;
  ms_linear_rhs(&mm->lin, &mm->ms, h, rhs, diag);
}

static void linear_mul(force_system_t *s, const double *y, double *out) {
  ms_model_t *mm = s->ctx;
  ms_linear_mul(&mm->lin, &mm->ms, y, out);
}

/* Before every sub-step: external forces are valid for one sub-step only;
 * the surface is brought to the sub-step's positions so the contact hook
 * sees where the tissue is. */
/* f_ext back to zero: the touched nodes only under regional sleeping. */
static void clear_f_ext(ms_model_t *mm) {
  if (mm->regions && mm->reg.springs && mm->ntouched <= mm->ms.n) {
    for (size_t a = 0; a < mm->ntouched; a++) memset(mm->ms.f_ext + 3 * (size_t)mm->touched[a], 0, 3 * sizeof(double));
  } else {
    memset(mm->ms.f_ext, 0, 3 * mm->ms.n * sizeof(double));
  }
  mm->ntouched = 0;
}

static void pre_substep(force_system_t *s) {
  ms_model_t *mm = s->ctx;
  clear_f_ext(mm);
  coupling_set_clear(&mm->cpl);
  embed(mm);
  if (mm->m.hook) mm->m.hook(&mm->m, mm->m.hook_ctx);
  /* Without a tool spring the integrator keeps its fused kick-drift loop. */
  if (mm->m.implicit_tools) mm->ms.fs.correct_v = mm->cpl.n ? correct_v : NULL;
}

/* Total energy and the part that measures motion and deformation (kinetic +
 * elastic, >= 0), which scales the guard's tolerance. */
static double energy_parts(const ms_model_t *mm, double *active) {
  const mass_spring_t *ms = &mm->ms;
  double total = mass_spring_energy(ms), grav = 0;
  for (size_t i = 0; i < ms->n; i++)
    grav -= ms->mass[i] * (ms->p.gravity[0] * ms->x[3 * i] + ms->p.gravity[1] * ms->x[3 * i + 1] +
                           ms->p.gravity[2] * ms->x[3 * i + 2]);
  *active = total - grav;
  return total;
}

/* One implicit sub-step of length h under the energy guard (file comment). */
static void guarded_implicit(ms_model_t *mm, double h) {
  mass_spring_t *ms = &mm->ms;
  size_t bytes = 3 * ms->n * sizeof(double);
  const double h_min = h / 256;
  double t = 0, hs = h, active, e_old = energy_parts(mm, &active);
  while (h - t > 1e-12 * h) {
    if (hs > h - t) hs = h - t;
    memcpy(mm->try_x, ms->x, bytes);
    memcpy(mm->try_v, ms->v, bytes);
    integrator_substep(&mm->it, &ms->fs, hs); /* the hook sets f_ext for this attempt */
    double work = 0;
    for (size_t c = 0; c < 3 * ms->n; c++) work += ms->f_ext[c] * (ms->x[c] - mm->try_x[c]);
    double active_new, e_new = energy_parts(mm, &active_new);
    int accept = !isfinite(e_new) /* the step's finite check rolls back */ || hs <= h_min ||
                 e_new - e_old - work <= 1e-3 * (active + fabs(work)) + 1e-12 * fabs(e_old);
    if (!accept) {
      memcpy(ms->x, mm->try_x, bytes);
      memcpy(ms->v, mm->try_v, bytes);
      hs *= 0.5;
      continue;
    }
    t += hs;
    e_old = e_new;
    active = active_new;
    if (hs < h) hs *= 2;
    if (!isfinite(e_new)) break;
  }
}

/* Regional sleeping for this step: 2 when it runs and guards the step
 * itself (ms_regions_begin_step: the step then costs what its awake nodes
 * cost), 1 when it runs but was (re)built now (after a topology change, a
 * change of material, a rollback or a write from outside: derived again
 * from the state, and the step is guarded over every node), 0 when it does
 * not run (off, or out of memory: every node integrated). */
static int regions_ready(ms_model_t *mm) {
  if (!mm->regions) return 0;
  mass_spring_t *ms = &mm->ms;
  int written = mm->m.outside_writes != mm->seen_writes;
  if (ms_regions_current(&mm->reg, ms) && !memcmp(&mm->reg_p, &ms->p, sizeof ms->p) &&
      mm->reg_damping_scale == ms->damping_scale && mm->reg_k_scale == ms->k_scale &&
      ms_regions_begin_step(&mm->reg, ms, written) == 0)
    return 2;
  verr_t err;
  uint32_t *t = realloc(mm->touched, (ms->n + 1) * sizeof *t);
  if (t) mm->touched = t;
  if (!t || ms_regions_build(&mm->reg, ms, &err)) return 0;
  mm->ntouched = ms->n + 1; /* f_ext's state unknown: the next clear is a full one */
  mm->reg_p = ms->p;
  mm->reg_damping_scale = ms->damping_scale;
  mm->reg_k_scale = ms->k_scale;
  return 1;
}

static int ms_step(model_t *m, double h) {
  ms_model_t *mm = (ms_model_t *)m;
  int ss = m->substeps < 1 ? 1 : m->substeps;
  double hs = h / ss;
  int regions = regions_ready(mm);
  mm->seen_writes = m->outside_writes;
  mm->moved_listed = 0;
  if (regions != 2) model_guard_save_finite(&mm->guard, mm->ms.x, mm->ms.v, mm->ms.n, NULL);
  for (int s = 0; s < ss; s++) {
    if (regions) {
      pre_substep(&mm->ms.fs);
      ms_regions_substep(&mm->reg, &mm->ms, hs);
    } else if (mm->it.kind == INT_IMPLICIT_EULER) {
      guarded_implicit(mm, hs);
    } else {
      integrator_substep(&mm->it, &mm->ms.fs, hs);
    }
  }
  clear_f_ext(mm);
  int rc;
  if (regions == 2) {
    rc = ms_regions_end_step(&mm->reg, &mm->ms, &m->rollbacks);
    mm->moved_listed = 1; /* the guard's nodes, restored or not */
  } else {
    rc = model_guard_check(&mm->guard, mm->ms.x, mm->ms.v, mm->ms.n, NULL, &m->rollbacks);
    /* The restored state is not what the sleeping nodes were decided on:
     * derived again at the next step (after whatever the runtime does). */
    if (rc < 0) mm->reg.springs = NULL;
  }
  embed(mm);
  return rc;
}

static void ms_destroy(model_t *m) {
  ms_model_t *mm = (ms_model_t *)m;
  integrator_destroy(&mm->it);
  mass_spring_destroy(&mm->ms);
  if (mm->tet) {
    tet_mesh_free(&mm->tm);
    tet_embedding_free(&mm->emb);
  }
  model_guard_free(&mm->guard);
  coupling_set_free(&mm->cpl);
  ms_linear_free(&mm->lin);
  ms_regions_free(&mm->reg);
  free(mm->touched);
  free(mm->surf_buf);
  free(mm->surf_rest_buf);
  free(mm->tris);
  free(mm->try_x);
  free(mm->try_v);
  free(mm->eig_k);
  free(mm->eig_y);
  free(mm);
}

static double ms_energy(const model_t *m) { return mass_spring_energy(&((const ms_model_t *)m)->ms); }

static double surface_error(const model_t *m) { return mass_spring_max_strain(&((const ms_model_t *)m)->ms); }

static double tet_error(const model_t *m) {
  const ms_model_t *mm = (const ms_model_t *)m;
  double v = 0;
  for (size_t i = 0; i < mm->tm.ntets; i++) v += tet_volume(&mm->tm, mm->ms.x, i);
  return mm->volume0 > 0 ? fabs(v / mm->volume0 - 1) : NAN;
}

static void surface_add_force(model_t *m, uint32_t i, const double f[3]) {
  ms_model_t *mm = (ms_model_t *)m;
  if (i >= mm->ms.n) return;
  mass_spring_add_force(&mm->ms, i, f);
  if (mm->regions && mm->reg.springs) {
    if (mm->ntouched < mm->ms.n) mm->touched[mm->ntouched] = i;
    if (mm->ntouched <= mm->ms.n) mm->ntouched++; /* past n: the next clear is a full one */
    ms_regions_touch(&mm->reg, &mm->ms, i);
  }
}

/* The embedded vertex moves as sum_k w_k x_k, so by virtual work a force on
 * it acts on node k with weight w_k. */
static void tet_add_force(model_t *m, uint32_t i, const double f[3]) {
  ms_model_t *mm = (ms_model_t *)m;
  if (i >= mm->emb.nsurf) return;
  const uint32_t *q = mm->tm.tets + 4 * (size_t)mm->emb.tet[i];
  for (int k = 0; k < 4; k++) {
    double w = mm->emb.bary[4 * (size_t)i + k], fk[3] = {w * f[0], w * f[1], w * f[2]};
    mass_spring_add_force(&mm->ms, q[k], fk);
  }
}

/* A tool spring in node terms: surface vertex i is node i. */
static void surface_add_coupling(model_t *m, double k, size_t nw, const uint32_t *wi, const double *w, size_t nb,
                                 const uint32_t *bi, const double *b) {
  ms_model_t *mm = (ms_model_t *)m;
  if (!m->implicit_tools) return;
  coupling_set_t *cs = &mm->cpl;
  coupling_begin(cs, k);
  int reg = mm->regions && mm->reg.springs;
  for (size_t j = 0; j < nw; j++)
    if (wi[j] < mm->ms.n) {
      coupling_push_w(cs, wi[j], w[j]);
      if (reg) ms_regions_touch(&mm->reg, &mm->ms, wi[j]);
    }
  for (size_t l = 0; l < nb; l++)
    if (bi[l] < mm->ms.n) {
      coupling_push_b(cs, bi[l], b[l]);
      if (reg) ms_regions_touch(&mm->reg, &mm->ms, bi[l]);
    }
  coupling_end(cs);
}

/* The same through the embedding: surface vertex i moves as sum_k e_k x_k
 * over its tetrahedron's nodes, so both weight sets spread by e. */
static void tet_add_coupling(model_t *m, double k, size_t nw, const uint32_t *wi, const double *w, size_t nb,
                             const uint32_t *bi, const double *b) {
  ms_model_t *mm = (ms_model_t *)m;
  if (!m->implicit_tools) return;
  coupling_set_t *cs = &mm->cpl;
  coupling_begin(cs, k);
  for (int pass = 0; pass < 2; pass++) {
    size_t cnt = pass ? nb : nw;
    const uint32_t *idx = pass ? bi : wi;
    const double *wt = pass ? b : w;
    for (size_t j = 0; j < cnt; j++) {
      if (idx[j] >= mm->emb.nsurf) continue;
      const uint32_t *q = mm->tm.tets + 4 * (size_t)mm->emb.tet[idx[j]];
      for (int c = 0; c < 4; c++) {
        double e = mm->emb.bary[4 * (size_t)idx[j] + c] * wt[j];
        if (pass)
          coupling_push_b(cs, q[c], e);
        else
          coupling_push_w(cs, q[c], e);
      }
    }
  }
  coupling_end(cs);
}

static int surface_save_topology(const model_t *m, state_blob_t *b);
static int surface_restore_topology(model_t *m, state_blob_t *b, size_t nnodes, const double *x, const double *v,
                                    verr_t *err);

static const model_edit_ops_t SURFACE_EDIT;

/* Under regional sleeping with the step guarded by the regions, every node
 * the step may change is in the guard's list before it moves (awake at
 * the start, or woken: ms_regions.h); otherwise any node may move. */
static size_t surface_moved(const model_t *m, const uint32_t **idx) {
  const ms_model_t *mm = (const ms_model_t *)m;
  if (!mm->regions || !mm->reg.springs || !mm->reg.in_step || m->surf_x != mm->ms.x) return SIZE_MAX;
  *idx = mm->reg.gidx;
  return mm->reg.gn;
}

/* The same list after the step (model.h last_step_moved), while nothing
 * wrote the state from outside since. */
static size_t last_step_moved(const model_t *m, const uint32_t **idx) {
  const ms_model_t *mm = (const ms_model_t *)m;
  if (!mm->moved_listed || m->outside_writes != mm->seen_writes || m->surf_x != mm->ms.x) return SIZE_MAX;
  *idx = mm->reg.gidx;
  return mm->reg.gn;
}

static const model_ops_t SURFACE_OPS = {.name = "mass_spring_surface",
                                        .step = ms_step,
                                        .destroy = ms_destroy,
                                        .energy = ms_energy,
                                        .error_estimate = surface_error,
                                        .add_surface_force = surface_add_force,
                                        .add_surface_coupling = surface_add_coupling,
                                        .save_topology = surface_save_topology,
                                        .restore_topology = surface_restore_topology,
                                        .edit = &SURFACE_EDIT,
                                        .surface_moved = surface_moved,
                                        .last_step_moved = last_step_moved};
static const model_ops_t TET_OPS = {.name = "mass_spring_tet",
                                    .step = ms_step,
                                    .destroy = ms_destroy,
                                    .energy = ms_energy,
                                    .error_estimate = tet_error,
                                    .add_surface_force = tet_add_force,
                                    .add_surface_coupling = tet_add_coupling};

/* Stable dt of the scheme for this system (see the file comment). */
static int substeps_from(ms_model_t *mm, integrator_kind_t kind, double lk, double lc, verr_t *err) {
  mass_spring_t *ms = &mm->ms;
  double m_node = ms->p.mass / (double)ms->n;
  double lk0 = (ms->p.home_stiffness + mm->tool_stiffness) / m_node, lc0 = ms->p.home_damping / m_node;
  if (kind == INT_SYMPLECTIC_EULER && mm->requested_substeps <= 0 && lc > 0) {
    /* Damping-capped sub-steps (file comment): the fewest n whose h = dt / n
     * is stable with the edge dampers' rate capped at MS_DAMPING_CAP / h. */
    for (int n = 1; n <= INTEGRATOR_MAX_SUBSTEPS; n++) {
      double h = mm->dt / n, scale = fmin(1.0, MS_DAMPING_CAP / (h * lc));
      double stable = fmin(integrator_stable_dt(kind, lk, lc * scale), integrator_stable_dt(kind, lk0, lc0));
      if (h <= 0.9 * stable) {
        ms->damping_scale = scale;
        mm->m.substeps = n;
        mm->m.stable_dt = stable;
        return 0;
      }
    }
  }
  ms->damping_scale = 1;
  return integrator_choose_substeps(kind, mm->dt, mm->requested_substeps, lk, lc, lk0, lc0,
                                    "lower material stiffness, damping or tool stiffness, raise the mass, or use "
                                    "implicit_euler (explicit_euler needs damping)",
                                    &mm->m.substeps, &mm->m.stable_dt, err);
}

static int choose_substeps(ms_model_t *mm, integrator_kind_t kind, verr_t *err) {
  double lk, lc;
  if (mass_spring_eigen_bounds(&mm->ms, mm->tool_stiffness, &lk, &lc)) return verr_set(err, "out of memory");
  return substeps_from(mm, kind, lk, lc, err);
}

static model_t *ms_create(const model_params_t *p, int tet, verr_t *err) {
  const scene_organ_t *cfg = p->cfg;
  int kind = integrator_parse(cfg->integrator);
  if (kind < 0) {
    verr_set(err, "integrator '%s' is not known", cfg->integrator);
    return NULL;
  }
  if (!(p->dt > 0) || !(p->tool_stiffness >= 0)) {
    verr_set(err, "mass-spring: dt must be > 0 and tool stiffness >= 0");
    return NULL;
  }
  ms_model_t *mm = calloc(1, sizeof *mm);
  if (!mm) {
    verr_set(err, "out of memory");
    return NULL;
  }
  mm->tet = tet;
  mm->dt = p->dt;
  /* Symplectic Euler and implicit_pcg take the tool springs implicitly
   * (coupling.h): the sub-steps then follow the tissue alone. */
  int coupled = kind == INT_SYMPLECTIC_EULER || kind == INT_IMPLICIT_PCG;
  mm->tool_stiffness = coupled ? 0 : p->tool_stiffness;
  mm->requested_substeps = cfg->solver.substeps;
  const mesh_t *s = p->surface;
  ms_params_t mp = {.mass = cfg->material.mass,
                    .stiffness = cfg->material.stiffness,
                    .damping = cfg->material.damping,
                    .home_stiffness = cfg->material.home_stiffness,
                    .home_damping = cfg->material.home_damping,
                    .gravity = {p->gravity[0], p->gravity[1], p->gravity[2]}};
  int rc;
  if (tet) {
    rc = model_volume_obtain(p, &mm->tm, &mm->emb, err);
    if (rc == 0) rc = mass_spring_create_tets(&mm->ms, &mm->tm, &mp, err);
    if (rc) {
      tet_mesh_free(&mm->tm);
      tet_embedding_free(&mm->emb);
      free(mm);
      return NULL;
    }
  } else if (mass_spring_create_surface(&mm->ms, s, &mp, err)) {
    free(mm);
    return NULL;
  }
  mm->ms.fs.ctx = mm;
  mm->ms.fs.pre_substep = pre_substep;
  if (coupled) {
    mm->ms.fs.correct_v = correct_v;
    mm->m.implicit_tools = 1;
    if (coupling_set_init(&mm->cpl, 256, 8192, err)) {
      ms_destroy(&mm->m);
      return NULL;
    }
  }
  if (kind == INT_IMPLICIT_PCG) {
    if (ms_linear_reserve(&mm->lin, mm->ms.nsprings, err)) {
      ms_destroy(&mm->m);
      return NULL;
    }
    mm->ms.fs.linearize = linearize;
    mm->ms.fs.linear_mul = linear_mul;
  }
  /* Regional sleeping: the live default (surface, symplectic Euler). */
  mm->regions = !tet && kind == INT_SYMPLECTIC_EULER && cfg->solver.region_force > 0;
  ms_regions_init(&mm->reg, cfg->solver.region_force, cfg->solver.region_speed);
  /* Conjugate gradients need a definite matrix (see mass_spring.h). */
  mm->ms.definite_jacobian = kind == INT_IMPLICIT_EULER || kind == INT_IMPLICIT_PCG;
  if (cfg->fixed_below_set) mass_spring_fix_below(&mm->ms, cfg->fixed_below);

  size_t n = mm->ms.n;
  int guard_rc = model_guard_reserve(&mm->guard, n);
  mm->tris = malloc(3 * s->ntris * sizeof(uint32_t) + 1);
  mm->tri_cap = s->ntris;
  if (tet) {
    mm->surf_buf = malloc(3 * s->nverts * sizeof(double) + 1);
    mm->surf_rest_buf = malloc(3 * s->nverts * sizeof(double) + 1);
  }
  if (kind == INT_IMPLICIT_EULER) {
    mm->try_x = malloc(3 * n * sizeof(double));
    mm->try_v = malloc(3 * n * sizeof(double));
  }
  if (guard_rc || !mm->tris || (tet && (!mm->surf_buf || !mm->surf_rest_buf)) ||
      (kind == INT_IMPLICIT_EULER && (!mm->try_x || !mm->try_v))) {
    verr_set(err, "out of memory for %zu nodes", n);
    ms_destroy(&mm->m);
    return NULL;
  }
  model_guard_save(&mm->guard, mm->ms.x, mm->ms.v, n, NULL);
  memcpy(mm->tris, s->tris, 3 * s->ntris * sizeof(uint32_t));

  model_t *m = &mm->m;
  m->ops = tet ? &TET_OPS : &SURFACE_OPS;
  m->error_kind = tet ? "volume_error" : "max_edge_strain";
  m->nnodes = n;
  m->x = mm->ms.x;
  m->v = mm->ms.v;
  m->x_rest = mm->ms.x_rest;
  m->ntets = tet ? mm->tm.ntets : 0;
  m->nsurf = s->nverts;
  m->nsurf_tris = s->ntris;
  m->surf_tris = mm->tris;
  if (tet) {
    /* The rest surface is the embedding of the rest nodes, so surf_x starts
     * exactly at surf_rest even where a vertex's weights extrapolate. */
    tet_embedding_apply(&mm->emb, &mm->tm, mm->ms.x_rest, mm->surf_rest_buf);
    memcpy(mm->surf_buf, mm->surf_rest_buf, 3 * s->nverts * sizeof(double));
    m->surf_x = mm->surf_buf;
    m->surf_rest = mm->surf_rest_buf;
    for (size_t i = 0; i < mm->tm.ntets; i++) mm->volume0 += tet_volume(&mm->tm, mm->tm.x, i);
  } else {
    m->surf_x = mm->ms.x;
    m->surf_rest = mm->ms.x_rest;
  }
  if (choose_substeps(mm, (integrator_kind_t)kind, err) ||
      integrator_init(&mm->it, (integrator_kind_t)kind, n, cfg->solver.cg_tolerance, cfg->solver.cg_max_iterations,
                      err)) {
    ms_destroy(m);
    return NULL;
  }
  return m;
}

model_t *model_mass_spring_surface_create(const model_params_t *p, verr_t *err);
model_t *model_mass_spring_tet_create(const model_params_t *p, verr_t *err);

model_t *model_mass_spring_surface_create(const model_params_t *p, verr_t *err) { return ms_create(p, 0, err); }
model_t *model_mass_spring_tet_create(const model_params_t *p, verr_t *err) { return ms_create(p, 1, err); }

mass_spring_t *model_mass_spring_surface_system(model_t *m) {
  return m && m->ops == &SURFACE_OPS ? &((ms_model_t *)m)->ms : NULL;
}

int model_mass_spring_cg_counts(const model_t *m, uint64_t *iterations, uint64_t *steps) {
  if (!m || (m->ops != &SURFACE_OPS && m->ops != &TET_OPS)) return -1;
  const ms_model_t *mm = (const ms_model_t *)m;
  if (mm->it.kind != INT_IMPLICIT_PCG) return -1;
  *iterations = mm->it.cg_iterations_total;
  *steps = mm->it.implicit_steps;
  return 0;
}

int model_mass_spring_region_counts(const model_t *m, ms_region_counts_t *out) {
  if (!m || m->ops != &SURFACE_OPS) return -1;
  const ms_model_t *mm = (const ms_model_t *)m;
  if (!mm->regions) return -1;
  const ms_regions_t *r = &mm->reg;
  *out = (ms_region_counts_t){.substeps = r->substeps,
                              .node_updates = r->node_updates,
                              .block_evals = r->block_evals,
                              .wakes = r->wakes,
                              .sleeps = r->sleeps,
                              .builds = r->builds,
                              .sleeper_checks = r->sleeper_checks,
                              .awake = r->nawake,
                              .nodes = mm->ms.n,
                              .springs = mm->ms.nsprings};
  return 0;
}

const ms_regions_t *model_mass_spring_regions(const model_t *m) {
  if (!m || m->ops != &SURFACE_OPS) return NULL;
  const ms_model_t *mm = (const ms_model_t *)m;
  return mm->regions && mm->reg.springs ? &mm->reg : NULL;
}

/* realloc that keeps *p on failure; NULL stays NULL. */
static int grow_buf(double **p, size_t count) {
  if (!*p) return 0;
  double *q = realloc(*p, count * sizeof(double) + 1);
  if (!q) return -1;
  *p = q;
  return 0;
}

static int ms_reserve(model_t *m, size_t cap, int with_f_res, verr_t *err) {
  ms_model_t *mm = (ms_model_t *)m;
  if (m->ops != &SURFACE_OPS) return verr_set(err, "topology changes need a mass_spring_surface model");
  size_t old = mm->ms.cap;
  if (cap > old) cap = cap < old + old / 2 ? old + old / 2 : cap;
  if (mass_spring_reserve(&mm->ms, cap, with_f_res, err)) return -1;
  if (mm->ms.cap > old || mm->it.n < mm->ms.cap) {
    size_t c3 = 3 * mm->ms.cap;
    if (model_guard_reserve(&mm->guard, mm->ms.cap) || grow_buf(&mm->try_x, c3) || grow_buf(&mm->try_v, c3) ||
        grow_buf(&mm->eig_k, c3) || grow_buf(&mm->eig_y, c3))
      return verr_set(err, "out of memory for %zu nodes", mm->ms.cap);
    integrator_t it;
    if (integrator_init(&it, mm->it.kind, mm->ms.cap, mm->it.cg_tolerance, mm->it.cg_max_iterations, err)) return -1;
    integrator_destroy(&mm->it);
    mm->it = it;
  }
  /* The arrays may have moved: the model's view follows (the caller bumps
   * topology_version through commit before anyone steps again); regional
   * sleeping is rebuilt (every node awake) at the next step. */
  mm->reg.springs = NULL;
  m->x = m->surf_x = mm->ms.x;
  m->v = mm->ms.v;
  m->x_rest = m->surf_rest = mm->ms.x_rest;
  return 0;
}

static int ms_prepare(model_t *m, verr_t *err) {
  ms_model_t *mm = (ms_model_t *)m;
  if (m->ops != &SURFACE_OPS) return verr_set(err, "topology changes need a mass_spring_surface model");
  if (mm->eig_k) return 0;
  mm->eig_k = calloc(3 * mm->ms.cap + 1, sizeof(double));
  mm->eig_y = calloc(3 * mm->ms.cap + 1, sizeof(double));
  double lk, lc;
  if (!mm->eig_k || !mm->eig_y ||
      mass_spring_eigen_bounds_warm(&mm->ms, mm->tool_stiffness, mm->eig_k, mm->eig_y, 0, &lk, &lc)) {
    free(mm->eig_k);
    free(mm->eig_y);
    mm->eig_k = mm->eig_y = NULL;
    return verr_set(err, "out of memory for %zu nodes", mm->ms.cap);
  }
  mm->lam_k = lk;
  return 0;
}

/* Moves the dominant vector to the new numbering (survivors keep their
 * components; new nodes get pseudo-random ones of the same size, so a mode
 * that lives in the new springs can grow). */
static void remap_vector(ms_model_t *mm, const uint32_t *old_to_new, size_t old_n, size_t n) {
  double *v = mm->eig_k, rms = 0;
  size_t first_new = 0;
  for (size_t i = 0; i < old_n; i++) {
    uint32_t j = old_to_new[i];
    rms += v3_dot(v + 3 * i, v + 3 * i);
    if (j == UINT32_MAX) continue;
    first_new++;
    if (j != i) memcpy(v + 3 * (size_t)j, v + 3 * i, 3 * sizeof(double));
  }
  rms = sqrt(rms / (double)(old_n ? old_n : 1));
  unsigned seed = 777;
  for (size_t c = 3 * first_new; c < 3 * n; c++) {
    seed = seed * 1664525u + 1013904223u;
    v[c] = rms * ((double)(seed >> 8) / 16777216.0 - 0.5);
  }
}

/* Sub-steps from lambda_k, with lambda_c derived from it (equal masses) or,
 * failing that, from the Gershgorin bound of C. */
static int substeps_from_k(ms_model_t *mm, double lk, verr_t *err) {
  double lc = mass_spring_lambda_c_from_k(&mm->ms, mm->tool_stiffness, lk);
  if (!isfinite(lc)) {
    double dummy_k;
    if (mass_spring_eigen_bounds(&mm->ms, mm->tool_stiffness, &dummy_k, &lc)) return verr_set(err, "out of memory");
  }
  mm->lam_k = lk;
  return substeps_from(mm, mm->it.kind, lk, lc, err);
}

static int ms_commit_nodes(model_t *m, size_t n, const uint32_t *old_to_new, size_t old_n, const uint32_t *tris,
                           size_t ntris, verr_t *err) {
  ms_model_t *mm = (ms_model_t *)m;
  if (m->ops != &SURFACE_OPS) return verr_set(err, "topology changes need a mass_spring_surface model");
  if (ntris > mm->tri_cap) {
    size_t cap = ntris < mm->tri_cap + mm->tri_cap / 2 ? mm->tri_cap + mm->tri_cap / 2 : ntris;
    uint32_t *t = realloc(mm->tris, 3 * cap * sizeof(uint32_t) + 1);
    if (!t) return verr_set(err, "out of memory for %zu triangles", cap);
    mm->tris = t;
    mm->tri_cap = cap;
  }
  /* implicit_pcg: room for every spring the new surface can have (its
   * unique edges, at most 3 per triangle) before the springs change. */
  if (mm->ms.fs.linearize && ms_linear_reserve(&mm->lin, 3 * ntris, err)) return -1;
  if (mass_spring_set_surface_topology(&mm->ms, n, tris, ntris, err)) return -1;
  mm->reg.springs = NULL; /* rebuilt, every node awake, at the next step */
  memcpy(mm->tris, tris, 3 * ntris * sizeof(uint32_t));
  model_guard_save(&mm->guard, mm->ms.x, mm->ms.v, n, NULL);
  m->nnodes = m->nsurf = n;
  m->nsurf_tris = ntris;
  m->surf_tris = mm->tris;
  m->x = m->surf_x = mm->ms.x;
  m->v = mm->ms.v;
  m->x_rest = m->surf_rest = mm->ms.x_rest;
  m->topology_version++;
  if (!mm->eig_k) { /* not prepared: a cold estimate now */
    double lk, lc;
    if (mass_spring_eigen_bounds(&mm->ms, mm->tool_stiffness, &lk, &lc)) return verr_set(err, "out of memory");
    return substeps_from(mm, mm->it.kind, lk, lc, err);
  }
  /* A bound valid at once, as safe as the old one (see the header): K_new = A + B with A the old K
   * less the cut springs and deleted nodes (its largest eigenvalue is at
   * most the old bound: fewer springs, a principal submatrix) and B the
   * springs touching new nodes plus their home springs, whose eigenvalues
   * B's Gershgorin bound caps; Weyl: lambda(A + B) <= lambda_old +
   * lambda(B). The whole system's Gershgorin bound caps it too. */
  size_t first_new = 0;
  for (size_t i = 0; i < old_n; i++) first_new += old_to_new[i] != UINT32_MAX;
  remap_vector(mm, old_to_new, old_n, n);
  double gb = mass_spring_gershgorin(&mm->ms, mm->tool_stiffness, first_new, mm->eig_y);
  double gf = mass_spring_gershgorin(&mm->ms, mm->tool_stiffness, n, mm->eig_y);
  mm->refining = 1;
  mm->refine_count = 0;
  mm->refine_lambda = 0;
  if (substeps_from_k(mm, fmin(mm->lam_k + gb, gf), err) == 0) return 0;
  /* The pessimistic bound asks for more sub-steps than allowed: estimate
   * now (a stall of one step) rather than keep sub-steps chosen for the
   * mesh before the change. */
  mm->refining = 0;
  double lk, lc;
  if (mass_spring_eigen_bounds_warm(&mm->ms, mm->tool_stiffness, mm->eig_k, mm->eig_y, 1, &lk, &lc))
    return verr_set(err, "out of memory");
  mm->lam_k = lk;
  return substeps_from(mm, mm->it.kind, lk, lc, err);
}

static int ms_refine(model_t *m, int iterations, verr_t *err) {
  ms_model_t *mm = (ms_model_t *)m;
  if (m->ops != &SURFACE_OPS || !mm->refining || !mm->eig_k) return 0;
  if (!mass_spring_power_steps(&mm->ms, mm->tool_stiffness, mm->eig_k, mm->eig_y, iterations, &mm->refine_count,
                               &mm->refine_lambda))
    return 0;
  mm->refining = 0;
  /* The 2 % margin of mass_spring_eigen_bounds, never above the bound set
   * at the change. */
  double lk = fmin(1.02 * mm->refine_lambda, mm->lam_k);
  if (!(lk > 0)) return 0;
  return substeps_from_k(mm, lk, err) ? -1 : 1;
}

/* ---- checkpoints (model.h save/restore_topology) ---------------------------- */

/* A cut surface model is its nodes (rest positions, masses, residual
 * forces), its triangles (the springs are their unique edges, rest lengths
 * from the rest positions: ms_commit_nodes, as after a cut) and
 * the sub-steps it had chosen. */
static int surface_save_topology(const model_t *m, state_blob_t *b) {
  const ms_model_t *mm = (const ms_model_t *)m;
  const mass_spring_t *ms = &mm->ms;
  sb_put_u64(b, ms->n);
  sb_put_u64(b, m->nsurf_tris);
  sb_put(b, ms->x_rest, 3 * ms->n * sizeof(double));
  sb_put(b, ms->mass, ms->n * sizeof(double));
  sb_put(b, ms->inv_mass, ms->n * sizeof(double));
  sb_put_u64(b, ms->f_res != NULL);
  if (ms->f_res) sb_put(b, ms->f_res, 3 * ms->n * sizeof(double));
  sb_put(b, mm->tris, 3 * m->nsurf_tris * sizeof(uint32_t));
  sb_put_u64(b, (uint64_t)m->substeps);
  sb_put_u64(b, m->topology_version);
  return b->bad ? -1 : 0;
}

static int all_finite(const double *p, size_t n) {
  double s = 0;
  for (size_t i = 0; i < n; i++) s += p[i] * 0.0;
  return s == 0.0; /* NaN or Inf anywhere makes it NaN */
}

static int surface_restore_topology(model_t *m, state_blob_t *b, size_t nnodes, const double *x, const double *v,
                                    verr_t *err) {
  ms_model_t *mm = (ms_model_t *)m;
  /* Per node at least 40 bytes follow (rest position, mass, inverse mass),
   * per triangle 12: counts beyond the bytes left are refused first. */
  size_t n = sb_count(b, 40);
  size_t nt = b->bad ? 0 : sb_count(b, 12);
  if (b->bad || n == 0 || nt == 0 || n != nnodes) return verr_set(err, "cut surface: bad node or triangle count");
  double *xr = malloc(3 * n * sizeof *xr), *mass = malloc(n * sizeof *mass), *im = malloc(n * sizeof *im);
  double *fres = NULL;
  uint32_t *tris = malloc(3 * nt * sizeof *tris);
  int rc = -1;
  if (!xr || !mass || !im || !tris) {
    verr_set(err, "cut surface: out of memory");
    goto out;
  }
  sb_get(b, xr, 3 * n * sizeof *xr);
  sb_get(b, mass, n * sizeof *mass);
  sb_get(b, im, n * sizeof *im);
  uint64_t has_fres = sb_get_u64(b);
  if (has_fres == 1) {
    if (!(fres = malloc(3 * n * sizeof *fres))) {
      verr_set(err, "cut surface: out of memory");
      goto out;
    }
    sb_get(b, fres, 3 * n * sizeof *fres);
  }
  sb_get(b, tris, 3 * nt * sizeof *tris);
  uint64_t substeps = sb_get_u64(b), version = sb_get_u64(b);
  if (b->bad || has_fres > 1) {
    verr_set(err, "cut surface: truncated");
    goto out;
  }
  if (!all_finite(xr, 3 * n) || !all_finite(mass, n) || !all_finite(im, n) || (fres && !all_finite(fres, 3 * n))) {
    verr_set(err, "cut surface: non-finite node data");
    goto out;
  }
  for (size_t i = 0; i < n; i++)
    if (!(mass[i] > 0) || im[i] < 0 || (im[i] > 0 && fabs(im[i] * mass[i] - 1) > 1e-9)) {
      verr_set(err, "cut surface: node %zu: bad mass", i);
      goto out;
    }
  for (size_t k = 0; k < 3 * nt; k++)
    if (tris[k] >= n) {
      verr_set(err, "cut surface: triangle %zu refers to node %u of %zu", k / 3, tris[k], n);
      goto out;
    }
  if (substeps < 1 || substeps > 256 || version == 0 || version > UINT32_MAX) {
    verr_set(err, "cut surface: bad sub-steps or topology version");
    goto out;
  }
  /* From here the model changes (the checkpoint loader rebuilds the scene
   * if anything below fails). A prepared model (one a scalpel may cut)
   * gets its dominant vector anew for the new topology. */
  int prepared = mm->eig_k != NULL;
  if (ms_reserve(m, n, fres != NULL, err)) goto out;
  memcpy(mm->ms.x, x, 3 * n * sizeof(double));
  memcpy(mm->ms.v, v, 3 * n * sizeof(double));
  memcpy(mm->ms.x_rest, xr, 3 * n * sizeof(double));
  memcpy(mm->ms.mass, mass, n * sizeof(double));
  memcpy(mm->ms.inv_mass, im, n * sizeof(double));
  if (fres)
    memcpy(mm->ms.f_res, fres, 3 * n * sizeof(double));
  else if (mm->ms.f_res)
    memset(mm->ms.f_res, 0, 3 * mm->ms.cap * sizeof(double));
  free(mm->eig_k);
  free(mm->eig_y);
  mm->eig_k = mm->eig_y = NULL;
  mm->refining = 0;
  if (ms_commit_nodes(m, n, NULL, 0, tris, nt, err)) goto out;
  if (prepared && ms_prepare(m, err)) goto out;
  m->substeps = (int)substeps; /* as the running model had them (its re-estimates are not saved) */
  m->topology_version = (uint32_t)version;
  rc = 0;
out:
  free(xr);
  free(mass);
  free(im);
  free(fres);
  free(tris);
  return rc;
}

/* ---- topology edits (model.h edit, MODEL_EDIT_SURFACE; model_mass_spring.h) -- */

static void ms_nodes(model_t *m, model_nodes_t *out) {
  mass_spring_t *ms = &((ms_model_t *)m)->ms;
  *out = (model_nodes_t){.n = ms->n,
                         .cap = ms->cap,
                         .x = ms->x,
                         .v = ms->v,
                         .x_rest = ms->x_rest,
                         .mass = ms->mass,
                         .inv_mass = ms->inv_mass,
                         .f_res = ms->f_res,
                         .f_ext = ms->f_ext,
                         .mass_total = ms->p.mass,
                         .edge_stiffness = ms->p.stiffness};
}

static size_t ms_rest_edges(const model_t *m, double *mean, double *max) {
  const mass_spring_t *ms = &((const ms_model_t *)m)->ms;
  double sum = 0, mx = 0;
  for (size_t s = 0; s < ms->nsprings; s++) {
    sum += ms->springs[s].rest;
    mx = fmax(mx, ms->springs[s].rest);
  }
  *mean = ms->nsprings ? sum / (double)ms->nsprings : 0;
  *max = mx;
  return ms->nsprings;
}

static int ms_commit(model_t *m, const model_topology_t *t, verr_t *err) {
  return ms_commit_nodes(m, t->n, t->old_to_new, t->old_n, t->tris, t->ntris, err);
}

static const model_edit_ops_t SURFACE_EDIT = {.kind = MODEL_EDIT_SURFACE,
                                              .nodes = ms_nodes,
                                              .rest_edges = ms_rest_edges,
                                              .reserve = ms_reserve,
                                              .commit = ms_commit,
                                              .prepare = ms_prepare,
                                              .refine = ms_refine};
