/* SPDX-License-Identifier: Apache-2.0 */
/* cut_scenario.h: random scalpel cuts through the spleen-size PBD model,
 * shared by the stability test (stab_cut.c, docs/numerics.md §5 case 15) and the
 * benchmark (tests/bench/bench_tet_cut.c). Header-only.
 *
 * The model: assets/meshes/spleen.obj through the tetrahedral builder at
 * 7 mm (about the seed's 711 nodes / 2,385 tetrahedra), "xpbd" with the scene
 * defaults (home springs 30 N/m keep the pieces in place), gravity, dt 5 ms
 * in one sub-step, 10 iterations (the test runs 800 steps on a mesh that
 * grows tenfold: one sub-step keeps it within its time budget).
 *
 * One random cut, an incision: from a random surface vertex S (outward
 * direction N = S - centre), a blade R long (R: largest half-extent of the
 * organ) along an axis tilted up to ~35 degrees from -N, its tip 0.05 to 0.2 R
 * deep (3 to 12 mm on the spleen), swept from 0.3 R before S to 0.1 to
 * 0.3 R after it along a random
 * direction across the axis, in 6 blade steps with one model step after
 * each; then the end of the cut and one more step. Incisions cross one
 * another after a few dozen cuts and some cut small pieces off.
 *
 * "Stable dt" for PBD/XPBD: these solvers have no explicit-scheme bound
 * (model stable_dt is INFINITY). Here it is the largest step h of
 * {1/60, 1/120, 1/240, 1/480} s (one sub-step, 10 iterations) for which
 * 0.5 s from rest under gravity on a fresh solver over the mesh keeps every
 * coordinate finite, no tetrahedron inverted and |sum V / sum V0 - 1| below
 * 5 %: the solver stays converged at that step. */
#ifndef VISCERA_CUT_SCENARIO_H
#define VISCERA_CUT_SCENARIO_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cutting/tet_cut.h"
#include "cutting/tet_model_cut.h"
#include "physics/pbd.h"
#include "scene.h"
#include "test_assets.h"
#include "test_rng.h"
#include "vmath.h"
#include "vtime.h"

#define CUT_DT 0.005

/* The spleen of the header from test_asset("meshes/spleen.obj"). */
static inline model_t *cut_spleen_model(mesh_t *surf, scene_organ_t *cfg, verr_t *err) {
  if (test_organ_load("spleen", surf)) {
    verr_set(err, "cannot load %s", test_asset("meshes/spleen.obj"));
    return NULL;
  }
  memset(cfg, 0, sizeof *cfg);
  snprintf(cfg->name, sizeof cfg->name, "spleen");
  snprintf(cfg->model, sizeof cfg->model, "xpbd");
  cfg->material = (scene_material_t){.mass = 0.1,
                                     .home_stiffness = 30,
                                     .home_damping = 0.005,
                                     .distance_stiffness = 1,
                                     .volume_stiffness = 1,
                                     .distance_compliance = 1e-4,
                                     .volume_compliance = 1e-6};
  cfg->solver = (scene_solver_t){.substeps = 1, .iterations = 10, .tet_size = 0.007};
  model_params_t mp = {.cfg = cfg, .surface = surf, .gravity = {0, 0, -9.81}, .dt = CUT_DT, .tool_stiffness = 300};
  model_t *m = model_pbd_create(&mp, err);
  if (!m) mesh_free(surf);
  return m;
}

typedef struct cut_record {
  size_t nodes, tets, surf_tris;
  double min_q_rest, min_q_now; /* radius ratio over all tetrahedra */
  double cut_ms;                /* all tet_model_cut_advance / _end calls of the cut (intersection, splits, rebuild) */
  double intersect_ms, topology_ms, rebuild_ms;
  double step_ms; /* median-free mean of the model steps during the cut */
  int finite;     /* every node and surface coordinate finite after the cut */
  int rc;         /* 0, or -1 when a call failed */
} cut_record_t;

static inline double cut_min_quality(const tet_cut_t *c, const double *x) {
  double q = INFINITY;
  for (size_t t = 0; t < c->ntets; t++) q = fmin(q, tet_cut_quality(c, x, t));
  return q;
}

static inline int cut_model_finite(const model_t *m) {
  for (size_t k = 0; k < 3 * m->nnodes; k++)
    if (!isfinite(m->x[k]) || !isfinite(m->v[k])) return 0;
  for (size_t k = 0; k < 3 * m->nsurf; k++)
    if (!isfinite(m->surf_x[k])) return 0;
  return 1;
}

/* One random cut (see the header) on m with its cutter tc, m's rest bounds lo..hi. */
static inline void cut_random(model_t *m, tet_model_cut_t *tc, const double *lo, const double *hi, unsigned *seed,
                              cut_record_t *r) {
  memset(r, 0, sizeof *r);
  double ctr[3], R = 0;
  for (int k = 0; k < 3; k++) {
    ctr[k] = 0.5 * (lo[k] + hi[k]);
    R = fmax(R, 0.5 * (hi[k] - lo[k]));
  }
  size_t sv0 = (size_t)(test_rng_lcg(seed) * (double)m->nsurf) % m->nsurf;
  double S[3], d[3], s[3], tmp[3], s2[3];
  v3_copy(S, m->surf_x + 3 * sv0);
  v3_sub(d, ctr, S);
  v3_normalize(d);
  for (int k = 0; k < 3; k++) d[k] += 0.7 * (test_rng_lcg(seed) - 0.5);
  v3_normalize(d);
  v3_set(tmp, fabs(d[0]) < 0.9 ? 1 : 0, fabs(d[0]) < 0.9 ? 0 : 1, 0);
  v3_cross(s, d, tmp);
  v3_normalize(s);
  double a = 2 * M_PI * test_rng_lcg(seed);
  v3_cross(s2, d, s);
  for (int k = 0; k < 3; k++) s[k] = cos(a) * s[k] + sin(a) * s2[k];
  double depth = R * (0.05 + 0.15 * test_rng_lcg(seed)), s_end = R * (0.1 + 0.2 * test_rng_lcg(seed));
  verr_t err;
  const pbd_t *sv = model_pbd_solver(m);
  double steps_s = 0;
  int nsteps = 0;
  for (int k = 0; k <= 6; k++) {
    double sp = -0.3 * R + (s_end + 0.3 * R) * k / 6.0, tip[3], han[3];
    for (int c = 0; c < 3; c++) {
      tip[c] = S[c] + sp * s[c] + depth * d[c];
      han[c] = tip[c] - R * d[c];
    }
    const tet_cut_t *c0 = tet_model_cut_mesh(tc);
    double i0 = c0 ? c0->stats.intersect_s : 0, t0 = c0 ? c0->stats.topology_s : 0;
    uint64_t a0 = vtime_mono_ns();
    if (tet_model_cut_advance(tc, tip, han, &err) < 0) r->rc = -1;
    double all = (double)(vtime_mono_ns() - a0) * 1e-6;
    const tet_cut_t *c = tet_model_cut_mesh(tc);
    r->cut_ms += all;
    double di = 1e3 * (c->stats.intersect_s - i0), dt = 1e3 * (c->stats.topology_s - t0);
    r->intersect_ms += di;
    r->topology_ms += dt;
    r->rebuild_ms += all - di - dt;
    uint64_t s0 = vtime_mono_ns();
    m->ops->step(m, CUT_DT);
    steps_s += (double)(vtime_mono_ns() - s0) * 1e-9;
    nsteps++;
  }
  const tet_cut_t *c = tet_model_cut_mesh(tc);
  double t0 = c->stats.topology_s;
  uint64_t a0 = vtime_mono_ns();
  if (tet_model_cut_end(tc, &err) < 0) r->rc = -1;
  double all = (double)(vtime_mono_ns() - a0) * 1e-6, dt = 1e3 * (c->stats.topology_s - t0);
  r->cut_ms += all;
  r->topology_ms += dt;
  r->rebuild_ms += all - dt;
  for (int k = 0; k < 1; k++) {
    uint64_t s0 = vtime_mono_ns();
    m->ops->step(m, CUT_DT);
    steps_s += (double)(vtime_mono_ns() - s0) * 1e-9;
    nsteps++;
  }
  sv = model_pbd_solver(m);
  r->nodes = sv->n;
  r->tets = sv->ntets;
  r->surf_tris = m->nsurf_tris;
  r->min_q_rest = cut_min_quality(c, c->x_rest);
  /* The cutter's positions are synced at each call; use the solver's. */
  tet_cut_t view = *c;
  view.x = sv->x;
  r->min_q_now = INFINITY;
  for (size_t t = 0; t < sv->ntets; t++) r->min_q_now = fmin(r->min_q_now, tet_cut_quality(&view, sv->x, t));
  r->step_ms = 1e3 * steps_s / nsteps;
  r->finite = cut_model_finite(m);
}

/* The "stable dt" of the header for a mesh (rest positions, tetrahedra). */
static inline double cut_stable_dt(size_t n, const double *x_rest, size_t ntets, const uint32_t *tets,
                                   const pbd_params_t *p0) {
  static const double H[4] = {1.0 / 60, 1.0 / 120, 1.0 / 240, 1.0 / 480};
  for (int k = 0; k < 4; k++) {
    pbd_params_t p = *p0;
    p.substeps = 1;
    p.iterations = 10;
    pbd_t s;
    verr_t err;
    if (pbd_create(&s, n, x_rest, ntets, tets, &p, &err)) return 0;
    int ok = 1;
    int steps = (int)lround(0.5 / H[k]);
    for (int i = 0; i < steps && ok; i++) ok = pbd_step(&s, H[k], NULL, NULL) == 0;
    pbd_errors_t e;
    pbd_errors(&s, &e);
    ok = ok && e.inverted == 0 && e.volume_global < 0.05;
    pbd_destroy(&s);
    if (ok) return H[k];
  }
  return 0;
}

#endif
