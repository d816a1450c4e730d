/* SPDX-License-Identifier: Apache-2.0 */
/* S7: a tetrahedral ball dropped on a plane.
 *
 * A sphere of radius 5 cm (icosphere, 642 vertices), 0.5 kg, edge springs
 * 1,000 N/m, released at rest with a 2 cm gap under it, falls under gravity
 * onto the plane z = 0 (at 0.064 s), squashes by a quarter of its radius,
 * bounces about 1 cm and lands again (0.36 s); 0.5 s are simulated (0.3 s
 * with --quick). Each landing amplifies differences: over 1 s, runs whose
 * bounce heights agree to 0.1 % drift apart by centimetres (e_x 10-25 %),
 * which would measure the contact's sensitivity, not the integrators. The ball is a scene model built by model_create
 * as a scene would build it (the surface filled with tetrahedra at tet_size 2.5 cm: 76 nodes; the surface embedded in
 * them): mass_spring_tet with every integrator, and XPBD and PBD. No model has ground contact; the benchmark adds it
 * through the model interface's contact hook (model.h: hook + add_surface_force), the way a tool's contact patch does:
 * before every sub-step each surface vertex below the plane gets a penalty force k_g (-z) upwards, k_g = 1,000 N/m per
 * vertex (2-4 mm at impact, under 1 mm lying), spread over its tetrahedron's nodes by the embedding. The penalty has no
 * damping: the hook sees positions, not velocities, so the ball's own damping (Kelvin-Voigt edges, XPBD/PBD ground
 * damping) is what takes the bounce out. The contact spring is passed to model_create as the stiffest tool spring, so
 * an explicit model's stable dt includes it (solver.substeps is fixed at 1 for the dt sweep, as in S4).
 *
 * What this costs PBD/XPBD: the penalty is an explicit force in their
 * prediction step, so it needs sub-steps shorter than 2 / sqrt(k_g w) (about
 * 3 ms here) whatever the compliance; a contact projection inside the
 * solver's iterations would not, but model.h has no such hook (the server's
 * tools push organs through forces too). Reported, not worked around.
 *
 * Measured per run: e_x against a converged run of the same model
 * (mass-spring: RK4 at a tiny step; XPBD and PBD: 256 sub-steps at 60 Hz,
 * 1 iteration; each checked by a run at half its step),
 * the bounce height (highest centre-of-mass height after the first
 * contact, minus the radius) and the penetration (deepest, and mean over
 * the last 0.1 s). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mesh.h"
#include "plot/plot.h"
#include "scene.h"

#include "numerics.h"

#define BALL_R 0.05
#define BALL_GAP 0.02
#define BALL_MASS 0.5
#define BALL_K 1000.0      /* N/m per edge spring; XPBD distance compliance 1/k */
#define BALL_C 0.05        /* N s/m Kelvin-Voigt per edge (mass-spring) */
#define BALL_GROUND_C 0.02 /* N s/m per node, ground damping (XPBD/PBD: their only damping) */
#define BALL_TET 0.025
#define K_GROUND 1000.0
#define SAMPLE (1.0 / 30)
#define MAXPTS 12

static const integrator_kind_t KINDS[] = {INT_EXPLICIT_EULER, INT_SYMPLECTIC_EULER, INT_VERLET, INT_RK4,
                                          INT_IMPLICIT_EULER};
#define NKINDS 5

/* ---- the ball's surface ------------------------------------------------------------ */

/* Midpoint of edge (a, b), created once: a linear search over the edges
 * made so far is enough for a few thousand. */
typedef struct midcache {
  uint32_t (*key)[2];
  uint32_t *val;
  size_t n;
} midcache_t;

static uint32_t midpoint(mesh_t *m, size_t *nv, midcache_t *mc, uint32_t a, uint32_t b) {
  if (a > b) {
    uint32_t t = a;
    a = b;
    b = t;
  }
  for (size_t i = 0; i < mc->n; i++)
    if (mc->key[i][0] == a && mc->key[i][1] == b) return mc->val[i];
  double *p = m->pos + 3 * *nv, len = 0;
  for (int k = 0; k < 3; k++) p[k] = 0.5 * (m->pos[3 * a + k] + m->pos[3 * b + k]), len += p[k] * p[k];
  for (int k = 0; k < 3; k++) p[k] /= sqrt(len);
  mc->key[mc->n][0] = a;
  mc->key[mc->n][1] = b;
  mc->val[mc->n++] = (uint32_t)*nv;
  return (uint32_t)(*nv)++;
}

/* Unit icosphere with `levels` subdivisions (levels 3: 642 vertices, 1,280
 * triangles), outward oriented, scaled by r and centred at c. */
static int icosphere(mesh_t *out, int levels, double r, const double c[3], verr_t *err) {
  const double t = (1 + sqrt(5.0)) / 2;
  const double V[12][3] = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                           {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  const uint32_t F[20][3] = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                             {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                             {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  size_t nt = 20, nv = 12, cap_t = 20, cap_v = 12;
  for (int l = 0; l < levels; l++) cap_t *= 4, cap_v = cap_v + 3 * (cap_t / 4) / 2;
  mesh_t m;
  if (mesh_alloc(&m, cap_v, cap_t, err)) return -1;
  for (int i = 0; i < 12; i++) {
    double len = sqrt(V[i][0] * V[i][0] + V[i][1] * V[i][1] + V[i][2] * V[i][2]);
    for (int k = 0; k < 3; k++) m.pos[3 * i + k] = V[i][k] / len;
  }
  memcpy(m.tris, F, sizeof F);
  uint32_t *tmp = malloc(3 * cap_t * sizeof *tmp);
  midcache_t mc = {malloc(cap_v * sizeof *mc.key), malloc(cap_v * sizeof *mc.val), 0};
  if (!tmp || !mc.key || !mc.val) {
    free(tmp);
    free(mc.key);
    free(mc.val);
    mesh_free(&m);
    return verr_set(err, "out of memory for the icosphere");
  }
  for (int l = 0; l < levels; l++) {
    mc.n = 0;
    size_t k = 0;
    for (size_t f = 0; f < nt; f++) {
      uint32_t a = m.tris[3 * f], b = m.tris[3 * f + 1], cc = m.tris[3 * f + 2];
      uint32_t ab = midpoint(&m, &nv, &mc, a, b), bc = midpoint(&m, &nv, &mc, b, cc),
               ca = midpoint(&m, &nv, &mc, cc, a);
      const uint32_t q[4][3] = {{a, ab, ca}, {b, bc, ab}, {cc, ca, bc}, {ab, bc, ca}};
      memcpy(tmp + 3 * k, q, sizeof q);
      k += 4;
    }
    nt = k;
    memcpy(m.tris, tmp, 3 * nt * sizeof *tmp);
  }
  free(tmp);
  free(mc.key);
  free(mc.val);
  m.nverts = nv;
  m.ntris = nt;
  /* Outward orientation: the signed volume must be positive. */
  double vol = 0;
  for (size_t f = 0; f < nt; f++) {
    const double *a = m.pos + 3 * m.tris[3 * f], *b = m.pos + 3 * m.tris[3 * f + 1], *d = m.pos + 3 * m.tris[3 * f + 2];
    vol += a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0]) + a[2] * (b[0] * d[1] - b[1] * d[0]);
  }
  if (vol < 0)
    for (size_t f = 0; f < nt; f++) {
      uint32_t tt = m.tris[3 * f + 1];
      m.tris[3 * f + 1] = m.tris[3 * f + 2];
      m.tris[3 * f + 2] = tt;
    }
  for (size_t i = 0; i < nv; i++)
    for (int k = 0; k < 3; k++) m.pos[3 * i + k] = c[k] + r * m.pos[3 * i + k];
  *out = m;
  return 0;
}

/* ---- contact and measures ----------------------------------------------------------- */

/* The ground: a penalty spring on every surface vertex below z = 0. */
static void ground_hook(model_t *m, void *ctx) {
  (void)ctx;
  for (uint32_t i = 0; i < m->nsurf; i++) {
    double z = m->surf_x[3 * (size_t)i + 2];
    if (z < 0) {
      const double f[3] = {0, 0, -K_GROUND * z};
      m->ops->add_surface_force(m, i, f);
    }
  }
}

typedef struct ball_obs {
  double T;
  int phase;      /* 0 falling, 1 first contact, 2 in the air after it, 3 back on the plane */
  double apex;    /* highest centre-of-mass z in phase 2 */
  double pen_max; /* deepest penetration */
  double pen_end; /* mean over the last 0.1 s */
  int n_end;
} ball_obs_t;

/* Every scene step (before it): contact phases and penetration. */
static void ball_before(sim_t *s, double t, void *ctx) {
  ball_obs_t *o = ctx;
  model_t *m = s->impl;
  if (t == 0) {
    double T = o->T;
    memset(o, 0, sizeof *o);
    o->T = T;
    o->apex = -INFINITY;
    /* A repeated run starts from x_init, but the model re-embeds its
     * surface only when it steps: at t = 0 surf_x may still be the last
     * run's. The ball is in the air then anyway. */
    return;
  }
  double com = 0, zmin = INFINITY;
  for (size_t i = 0; i < m->nnodes; i++) com += m->x[3 * i + 2];
  com /= (double)m->nnodes;
  for (size_t i = 0; i < m->nsurf; i++) zmin = fmin(zmin, m->surf_x[3 * i + 2]);
  double pen = zmin < 0 ? -zmin : 0;
  o->pen_max = fmax(o->pen_max, pen);
  if (o->phase == 0 && pen > 0)
    o->phase = 1;
  else if (o->phase == 1 && pen == 0)
    o->phase = 2;
  else if (o->phase == 2 && pen > 0)
    o->phase = 3;
  if (o->phase == 2) o->apex = fmax(o->apex, com);
  if (t >= o->T - 0.1 - 1e-12) {
    o->pen_end += pen;
    o->n_end++;
  }
}

static double bounce_height(const ball_obs_t *o) { return isfinite(o->apex) ? fmax(o->apex - BALL_R, 0) : 0; }

/* ---- building a ball model -------------------------------------------------------------- */

static sim_t *ball_sim(const mesh_t *sphere, const char *model, const char *integ, int substeps, int iterations,
                       double dt, verr_t *err) {
  char yaml[1024];
  static scene_t sc;
  snprintf(yaml, sizeof yaml,
           "scene: numerics_s7\norgans:\n  - name: ball\n    mesh: none.obj\n    model: %s\n    integrator: %s\n"
           "    solver: {substeps: %d, iterations: %d, tet_size: %g}\n"
           "    material: {mass: %g, stiffness: %g, damping: %g, home_stiffness: 0, home_damping: %g, "
           "distance_stiffness: 1, volume_stiffness: 1, distance_compliance: %g, volume_compliance: 1.0e-10}\n",
           model, strcmp(model, "mass_spring_tet") ? "symplectic_euler" : integ, substeps, iterations, BALL_TET,
           BALL_MASS, BALL_K, BALL_C, strcmp(model, "mass_spring_tet") ? BALL_GROUND_C : 0.0, 1 / BALL_K);
  if (scene_load_string(yaml, "numerics_s7", NULL, &sc, err)) return NULL;
  model_params_t mp = {
      .cfg = &sc.organs[0], .surface = sphere, .gravity = {0, 0, -9.81}, .dt = dt, .tool_stiffness = K_GROUND};
  model_t *m = model_create(&mp, err);
  if (!m) return NULL;
  m->hook = ground_hook;
  return sim_model(m, err);
}

typedef struct series {
  char label[96];
  int color, marker, n;
  double x[MAXPTS], err[MAXPTS], cost[MAXPTS];
} series_t;

typedef struct ball_ctx {
  nb_t *nb;
  const mesh_t *sphere;
  FILE *csv;
  double T, diag;
  size_t nnodes; /* of the tetrahedral ball, from the first model built */
} ball_ctx_t;

/* One run: returns 0 and fills o (caller frees) and obs. */
static int ball_run(const ball_ctx_t *bc, sim_t *s, double dt, int reps, run_out_t *o, ball_obs_t *obs) {
  verr_t err;
  obs->T = bc->T;
  run_spec_t sp = {
      .dt = dt, .T = bc->T, .sample_dt = SAMPLE, .reps = reps, .blowup = 1.0, .before_step = ball_before, .ctx = obs};
  if (run_sim(s, &sp, o, &err)) {
    nb_progress("S7: %s", err.msg);
    return -1;
  }
  return 0;
}

static void measure(const ball_ctx_t *bc, const char *model, const char *integ, int sub, int it, double dt,
                    const run_out_t *ref, const ball_obs_t *robs, series_t *se, double xval) {
  verr_t err;
  sim_t *s = ball_sim(bc->sphere, model, integ, sub, it, dt, &err);
  if (!s) {
    nb_progress("S7 %s %s: %s", model, integ, err.msg);
    return;
  }
  run_out_t o;
  ball_obs_t obs;
  if (ball_run(bc, s, dt, 3, &o, &obs)) {
    sim_destroy(s);
    return;
  }
  double e_end, e = ex_error(&o.traj, &ref->traj, NULL, bc->diag, &e_end);
  if (!o.stable) e = e_end = NAN;
  double bounce = bounce_height(&obs), pen_end = obs.n_end ? obs.pen_end / obs.n_end : NAN;
  if (bc->csv)
    fprintf(bc->csv, "%s,%s,%.9g,%d,%d,%d,%.4g,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e,%.3f,%.3f,%.6e\n", model, integ,
            dt, sub, it, o.stable, o.t_fail, e, e_end, o.stable ? bounce : NAN, bounce_height(robs),
            o.stable ? obs.pen_max : NAN, robs->pen_max, o.stable ? pen_end : NAN, robs->pen_end / robs->n_end,
            o.step_us_median, o.step_us_p95, o.wall_per_sim_s);
  nb_result(bc->nb, "S7", model, integ, dt, sub, it, "e_x", e, e_end, &o);
  if (se && se->n < MAXPTS) {
    se->x[se->n] = xval;
    se->err[se->n] = o.stable ? e : NAN;
    se->cost[se->n] = o.stable ? o.wall_per_sim_s : NAN;
    se->n++;
  }
  run_out_free(&o);
  sim_destroy(s);
}

/* Reference run of one model; returns 0 with ref and robs filled. */
static int reference(ball_ctx_t *bc, const char *model, const char *integ, int sub, double dt, run_out_t *ref,
                     ball_obs_t *robs, double *halving) {
  verr_t err;
  sim_t *s = ball_sim(bc->sphere, model, integ, sub, 1, dt, &err);
  if (!s) {
    nb_skip(bc->nb, "S7 %s reference: %s", model, err.msg);
    return -1;
  }
  bc->nnodes = s->n;
  if (ball_run(bc, s, dt, 1, ref, robs) || !ref->stable) {
    nb_skip(bc->nb, "S7 %s reference diverged", model);
    sim_destroy(s);
    return -1;
  }
  sim_destroy(s);
  *halving = NAN;
  if (!bc->nb->quick) {      /* the same at half the (sub-)step: how far the reference is converged */
    double half_dt = dt / 2; /* same sub-steps: half the sub-step */
    s = ball_sim(bc->sphere, model, integ, sub, 1, half_dt, &err);
    run_out_t r2;
    ball_obs_t o2;
    if (s && ball_run(bc, s, half_dt, 1, &r2, &o2) == 0) {
      *halving = ex_error(&ref->traj, &r2.traj, NULL, bc->diag, NULL);
      run_out_free(&r2);
    }
    sim_destroy(s);
  }
  nb_progress("S7 %s reference (%s, dt 1/%.0f s, %d sub-steps): bounce %.2f mm, penetration max %.2f mm, last 0.1 s "
              "%.2f mm; halving changes e_x by %.1e",
              model, integ, 1 / dt, sub, 1e3 * bounce_height(robs), 1e3 * robs->pen_max,
              1e3 * robs->pen_end / robs->n_end, *halving);
  return 0;
}

static void plot_series(plot_t *p, const series_t *s, int use_cost, int pareto) {
  double xs[MAXPTS];
  for (int i = 0; i < s->n; i++) xs[i] = use_cost ? s->cost[i] : s->x[i];
  plot_series_t *ps = plot_add(p, s->label, (size_t)s->n, xs, s->err, s->color, s->marker, PLOT_LINE_SOLID);
  if (ps) ps->pareto = pareto;
}

void scene_ball(nb_t *nb) {
  verr_t err;
  const double c[3] = {0, 0, BALL_R + BALL_GAP};
  mesh_t sphere;
  if (icosphere(&sphere, 3, BALL_R, c, &err)) {
    nb_skip(nb, "S7: %s", err.msg);
    return;
  }
  ball_ctx_t bc = {.nb = nb, .sphere = &sphere, .T = nb->quick ? 0.3 : 0.5};
  /* e_x scale: the box the ball sweeps (its diameter plus the drop). */
  bc.diag = sqrt(3.0) * 2 * BALL_R + BALL_GAP;
  const int NDT = nb->quick ? 7 : 9;
  /* The symplectic bound of the ball with the ground spring (the model's
   * own power iteration, sub-steps automatic). */
  double stable_sym = NAN;
  sim_t *probe = ball_sim(&sphere, "mass_spring_tet", "symplectic_euler", 0, 1, 1.0 / 60, &err);
  if (probe) {
    stable_sym = ((model_t *)probe->impl)->stable_dt;
    bc.nnodes = probe->n;
    sim_destroy(probe);
  }
  nb_progress("S7: %zu tetrahedral nodes; symplectic Euler needs dt < %.3g ms (ground spring included)", bc.nnodes,
              1e3 * stable_sym);
  nb_progress("S7 ball on a plane (%zu surface vertices, r %.0f mm, %.1f kg, ground k %.0f N/m per vertex), %.1f s",
              sphere.nverts, 1e3 * BALL_R, BALL_MASS, K_GROUND, bc.T);
  bc.csv = nb_csv(nb, "s7_ball.csv",
                  "model,integrator,dt,substeps,iterations,stable,t_fail,e_max,e_end,bounce_m,ref_bounce_m,"
                  "penetration_max_m,ref_penetration_max_m,penetration_rest_m,ref_penetration_rest_m,step_us_median,"
                  "step_us_p95,wall_s_per_sim_s");

  series_t ms[NKINDS];
  memset(ms, 0, sizeof ms);
  run_out_t ref;
  ball_obs_t robs;
  double halving, dt_ref = nb_dt(NDT + 1);
  char note_ms[200] = "", note_x[200] = "", note_p[200] = "";
  if (reference(&bc, "mass_spring_tet", "rk4", 1, dt_ref, &ref, &robs, &halving) == 0) {
    snprintf(
        note_ms, sizeof note_ms,
        "mass-spring ref RK4 1/%.0f s (halving: e_x %.0e): bounce %.1f mm, penetration max %.2f, last 0.1 s %.2f mm",
        1 / dt_ref, halving, 1e3 * bounce_height(&robs), 1e3 * robs.pen_max, 1e3 * robs.pen_end / robs.n_end);
    for (int ki = 0; ki < NKINDS; ki++) {
      snprintf(ms[ki].label, sizeof ms[ki].label, "mass-spring tet, %s", integ_label(KINDS[ki]));
      ms[ki].color = ki;
      ms[ki].marker = ki;
      nb_progress("S7: mass_spring_tet %s x %d steps", integrator_name(KINDS[ki]), NDT);
      for (int d = 0; d < NDT; d++)
        measure(&bc, "mass_spring_tet", integrator_name(KINDS[ki]), 1, 1, nb_dt(d), &ref, &robs, &ms[ki], nb_dt(d));
    }
    run_out_free(&ref);
  }

  static const int SUBS[] = {1, 2, 4, 8, 16, 32, 64};
  const int NSUB = nb->quick ? 5 : 7, REF_SUB = nb->quick ? 128 : 256;
  const double dt60 = 1.0 / 60;
  series_t xs = {.color = 5, .marker = 5}, pb = {.color = 9, .marker = 1};
  snprintf(xs.label, sizeof xs.label, "XPBD, 60 Hz, 1 iteration, sub-steps 1-%d", SUBS[NSUB - 1]);
  snprintf(pb.label, sizeof pb.label, "PBD, 60 Hz, 1 iteration, sub-steps 1-%d", SUBS[NSUB - 1]);
#ifdef NUMERICS_HAVE_PBD
  const char *pm[2] = {"xpbd", "pbd"};
  series_t *ps[2] = {&xs, &pb};
  char *notes[2] = {note_x, note_p};
  for (int k = 0; k < 2; k++) {
    if (reference(&bc, pm[k], "gauss_seidel", REF_SUB, dt60, &ref, &robs, &halving)) continue;
    snprintf(notes[k], 200,
             "%s ref %d sub-steps (dt/2: e_x %.0e): bounce %.1f mm, penetration max %.2f, last 0.1 s "
             "%.2f mm",
             k ? "PBD" : "XPBD", REF_SUB, halving, 1e3 * bounce_height(&robs), 1e3 * robs.pen_max,
             1e3 * robs.pen_end / robs.n_end);
    nb_progress("S7: %s at 60 Hz, sub-steps 1..%d x 1 iteration", pm[k], SUBS[NSUB - 1]);
    for (int i = 0; i < NSUB; i++)
      measure(&bc, pm[k], "gauss_seidel", SUBS[i], 1, dt60, &ref, &robs, ps[k], dt60 / SUBS[i]);
    run_out_free(&ref);
  }
#else
  nb_skip(nb, "S7 PBD/XPBD: pbd.c is not in viscera_sim in this build");
#endif
  if (bc.csv) fclose(bc.csv);

  plot_t p;
  char title[160];
  snprintf(title, sizeof title, "S7 ball dropped on a plane: work-precision (%.1f s)", bc.T);
  plot_init(&p, title, "wall time per simulated second (s, one core)", "e_x: max RMS position error / box diagonal", 1,
            1);
  p.pareto = 1;
  snprintf(p.empty_suffix, sizeof p.empty_suffix, " (all diverged)");
  for (int ki = 0; ki < NKINDS; ki++) plot_series(&p, &ms[ki], 1, 1);
  plot_series(&p, &xs, 1, 1);
  plot_series(&p, &pb, 1, 1);
  plot_note(&p,
            "Each model against its own converged run (the front compares solver error only); ground = penalty %.0f "
            "N/m per surface vertex through the "
            "contact hook. Mass-spring: dt 1/30 ... 1/%.0f s, 1 sub-step. Missing points diverged.",
            K_GROUND, 1 / nb_dt(NDT - 1));
  plot_note(&p,
            "%.1f s: the first bounce and the second landing (every landing amplifies differences, so longer runs "
            "would measure the contact's sensitivity more than the schemes).",
            bc.T);
  if (note_ms[0]) plot_note(&p, "%s", note_ms);
  if (note_x[0]) plot_note(&p, "%s", note_x);
  if (note_p[0]) plot_note(&p, "%s", note_p);
  nb_plot(nb, &p, "plot1_work_precision_S7.png");
  plot_free(&p);

  plot_init(&p, "S7 ball dropped on a plane: error vs time step", "time step dt, or sub-step dt/n for XPBD/PBD (s)",
            "e_x: max RMS position error / box diagonal", 1, 1);
  snprintf(p.empty_suffix, sizeof p.empty_suffix, " (all diverged)");
  for (int ki = 0; ki < NKINDS; ki++) {
    series_t t = ms[ki];
    double slope = plot_loglog_slope((size_t)t.n, t.x, t.err, 1e-12, 0.05, NULL);
    if (isfinite(slope))
      snprintf(t.label, sizeof t.label, "mass-spring tet, %s (slope %.2f)", integ_label(KINDS[ki]), slope);
    plot_series(&p, &t, 0, 0);
  }
  plot_series(&p, &xs, 0, 0);
  plot_series(&p, &pb, 0, 0);
  plot_note(&p, "Slopes: least squares over the points with e_x in (1e-12, 0.05). The hook sees the surface at the "
                "model's positions, not at RK4's stage positions, and the penalty has a kink at z = 0: low orders.");
  plot_note(&p, "Symplectic Euler and Verlet need dt < %.2g ms here (power iteration, ground spring included).",
            1e3 * stable_sym);
  plot_note(&p,
            "PBD/XPBD take the penalty as an explicit force: stable only with sub-steps below about 2/sqrt(k_g w) "
            "= %.1f ms.",
            1e3 * 2 / sqrt(K_GROUND / (BALL_MASS / (double)(bc.nnodes ? bc.nnodes : 1))));
  nb_plot(nb, &p, "plot2_error_vs_dt_S7.png");
  plot_free(&p);
  mesh_free(&sphere);
}
