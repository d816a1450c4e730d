/* SPDX-License-Identifier: Apache-2.0 */
/* sim: one stepping interface over force systems + integrators, PBD/XPBD
 * solvers and scene models, and the timed, sampled run loop. */
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "numerics.h"
#include "plot/plot.h"
#include "vstats.h"
#include "vtime.h"

/* ---- force system + integrator ------------------------------------------------ */

/* The integrator is handed a copy of the model's force system whose
 * callbacks count evaluations and then forward to the model's own, so the
 * cost table can report force evaluations for models that keep no count. */
typedef struct fs_impl {
  force_system_t wrap;
  force_system_t *orig;
  integrator_t it;
  double (*energy)(void *);
  void (*owner_free)(void *);
  void *owner;
  uint64_t calls;
} fs_impl_t;

static void wrap_forces(force_system_t *s, const double *x, const double *v, double *f) {
  fs_impl_t *w = s->ctx;
  w->calls++;
  w->orig->forces(w->orig, x, v, f);
}
static void wrap_stiffness(force_system_t *s, const double *x, double a, double b, const double *y, double *out) {
  fs_impl_t *w = s->ctx;
  w->orig->stiffness_mul(w->orig, x, a, b, y, out);
}
static void wrap_pre(force_system_t *s) {
  fs_impl_t *w = s->ctx;
  if (w->orig->pre_substep) w->orig->pre_substep(w->orig);
}

static int all_finite(const double *a, size_t n) {
  double sum = 0; /* NaN or Inf anywhere poisons the sum */
  for (size_t i = 0; i < n; i++) sum += a[i];
  return isfinite(sum);
}

static int fs_step(sim_t *s, double h) {
  fs_impl_t *w = s->impl;
  double hs = h / s->substeps;
  for (int k = 0; k < s->substeps; k++) integrator_substep(&w->it, &w->wrap, hs);
  s->evals = w->calls;
  return all_finite(s->x, 3 * s->n) && all_finite(s->v, 3 * s->n) ? 0 : -1;
}

static double fs_energy(sim_t *s) {
  fs_impl_t *w = s->impl;
  return w->energy ? w->energy(w->owner) : NAN;
}

static void fs_destroy(sim_t *s) {
  fs_impl_t *w = s->impl;
  integrator_destroy(&w->it);
  if (w->owner_free) w->owner_free(w->owner);
  free(w);
}

static sim_t *sim_new(size_t n, double *x, double *v, verr_t *err) {
  sim_t *s = calloc(1, sizeof *s);
  if (!s) return verr_set(err, "out of memory"), NULL;
  s->n = n;
  s->x = x;
  s->v = v;
  s->x_init = malloc(3 * n * sizeof(double));
  s->v_init = malloc(3 * n * sizeof(double));
  if (!s->x_init || !s->v_init) {
    free(s->x_init);
    free(s->v_init);
    free(s);
    verr_set(err, "out of memory for %zu nodes", n);
    return NULL;
  }
  sim_capture(s);
  s->substeps = s->iterations = 1;
  return s;
}

sim_t *sim_fs(force_system_t *fs, integrator_kind_t kind, int substeps, double cg_tol, int cg_max,
              double (*energy)(void *owner), void (*owner_free)(void *owner), void *owner, verr_t *err) {
  fs_impl_t *w = calloc(1, sizeof *w);
  if (!w) {
    if (owner_free) owner_free(owner);
    return verr_set(err, "out of memory"), NULL;
  }
  if (integrator_init(&w->it, kind, fs->n, cg_tol, cg_max, err)) {
    if (owner_free) owner_free(owner);
    free(w);
    return NULL;
  }
  w->orig = fs;
  w->wrap = *fs;
  w->wrap.ctx = w;
  w->wrap.forces = wrap_forces;
  w->wrap.stiffness_mul = fs->stiffness_mul ? wrap_stiffness : NULL;
  w->wrap.pre_substep = wrap_pre;
  w->energy = energy;
  w->owner_free = owner_free;
  w->owner = owner;
  sim_t *s = sim_new(fs->n, fs->x, fs->v, err);
  if (!s) {
    fs_destroy(&(sim_t){.impl = w});
    return NULL;
  }
  s->mass = fs->mass;
  s->substeps = substeps < 1 ? 1 : substeps;
  s->step = fs_step;
  s->energy = fs_energy;
  s->destroy = fs_destroy;
  s->impl = w;
  return s;
}

#ifdef NUMERICS_HAVE_PBD
/* ---- PBD / XPBD -------------------------------------------------------------------- */

static int pbd_sim_step(sim_t *s, double h) {
  pbd_t *p = s->impl;
  int rc = pbd_step(p, h, NULL, NULL);
  /* Constraint projections: every distance and volume constraint (and the
   * home constraints when present) once per iteration and sub-step. */
  uint64_t per = (uint64_t)p->nedges + p->ntets + (p->p.home_stiffness > 0 ? 3 * (uint64_t)p->n : 0);
  s->evals += (uint64_t)p->p.substeps * (uint64_t)p->p.iterations * per;
  return rc;
}
static double pbd_sim_energy(sim_t *s) {
  pbd_t *p = s->impl;
  return p->p.mode == PBD_MODE_XPBD ? pbd_energy(p) : NAN;
}
static void pbd_sim_destroy(sim_t *s) {
  pbd_destroy(s->impl);
  free(s->impl);
}

sim_t *sim_pbd(pbd_t *p, verr_t *err) {
  sim_t *s = sim_new(p->n, p->x, p->v, err);
  if (!s) {
    pbd_destroy(p);
    free(p);
    return NULL;
  }
  s->mass = p->mass;
  s->substeps = p->p.substeps;
  s->iterations = p->p.iterations;
  s->step = pbd_sim_step;
  s->energy = pbd_sim_energy;
  s->destroy = pbd_sim_destroy;
  s->impl = p;
  return s;
}

#endif

/* ---- scene model ------------------------------------------------------------------- */

static int model_sim_step(sim_t *s, double h) {
  model_t *m = s->impl;
  int rc = m->ops->step(m, h);
  s->evals += (uint64_t)m->substeps;
  return rc;
}
static double model_sim_energy(sim_t *s) {
  model_t *m = s->impl;
  return m->ops->energy ? m->ops->energy(m) : NAN;
}
static void model_sim_destroy(sim_t *s) { model_destroy(s->impl); }

sim_t *sim_model(model_t *m, verr_t *err) {
  sim_t *s = sim_new(m->nnodes, m->x, m->v, err);
  if (!s) {
    model_destroy(m);
    return NULL;
  }
  s->substeps = m->substeps;
  s->step = model_sim_step;
  s->energy = model_sim_energy;
  s->destroy = model_sim_destroy;
  s->impl = m;
  return s;
}

void sim_reset(sim_t *s) {
  memcpy(s->x, s->x_init, 3 * s->n * sizeof(double));
  memcpy(s->v, s->v_init, 3 * s->n * sizeof(double));
  if (s->step == model_sim_step) model_note_outside_write((model_t *)s->impl);
}

void sim_capture(sim_t *s) {
  memcpy(s->x_init, s->x, 3 * s->n * sizeof(double));
  memcpy(s->v_init, s->v, 3 * s->n * sizeof(double));
}

void sim_destroy(sim_t *s) {
  if (!s) return;
  s->destroy(s);
  free(s->x_init);
  free(s->v_init);
  free(s);
}

/* ---- runs --------------------------------------------------------------------------- */

void run_out_free(run_out_t *o) {
  free(o->traj.x);
  free(o->traj.extra);
  memset(o, 0, sizeof *o);
}

static int diverged(const sim_t *s, double blowup) {
  if (!all_finite(s->x, 3 * s->n)) return 1;
  double b2 = blowup * blowup;
  for (size_t i = 0; i < s->n; i++) {
    const double *a = s->x + 3 * i, *b = s->x_init + 3 * i;
    double d2 = (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
    if (!(d2 < b2)) return 1;
  }
  return 0;
}

int run_sim(sim_t *s, const run_spec_t *sp, run_out_t *out, verr_t *err) {
  memset(out, 0, sizeof *out);
  size_t nsteps = (size_t)llround(sp->T / sp->dt);
  size_t every = (size_t)llround(sp->sample_dt / sp->dt);
  if (every < 1 || fabs((double)every * sp->dt - sp->sample_dt) > 1e-9 * sp->sample_dt)
    return verr_set(err, "run: dt %g does not divide the sampling interval %g", sp->dt, sp->sample_dt);
  size_t ns = nsteps / every + 1;
  out->traj.n = s->n;
  out->traj.ns = ns;
  out->traj.nextra = sp->nextra;
  out->traj.x = calloc(ns * 3 * s->n, sizeof(double)); /* a run that stops early leaves zeros */
  out->traj.extra = sp->nextra ? calloc(ns * sp->nextra, sizeof(double)) : NULL;
  int reps = sp->reps < 1 ? 1 : sp->reps;
  double *step_us = malloc((nsteps ? nsteps : 1) * (size_t)reps * sizeof(double));
  if (!out->traj.x || (sp->nextra && !out->traj.extra) || !step_us) {
    free(step_us);
    run_out_free(out);
    return verr_set(err, "run: out of memory for %zu samples of %zu nodes", ns, s->n);
  }
  out->stable = 1;
  out->t_fail = NAN;
  size_t nst = 0;
  double spent = 0;
  for (int r = 0; r < reps; r++) {
    sim_reset(s);
    uint64_t evals0 = s->evals;
    int sample = r == 0;
    if (sample) {
      memcpy(out->traj.x, s->x, 3 * s->n * sizeof(double));
      if (sp->observe) sp->observe(s, 0, out->traj.extra, sp->ctx);
    }
    double total = 0;
    size_t k;
    for (k = 1; k <= nsteps; k++) {
      double t0 = (double)(k - 1) * sp->dt;
      if (sp->before_step) sp->before_step(s, t0, sp->ctx);
      uint64_t a = vtime_mono_ns();
      int rc = s->step(s, sp->dt);
      double us = (double)(vtime_mono_ns() - a) * 1e-3;
      total += us;
      step_us[nst++] = us;
      int bad = rc != 0;
      if (!bad && (k % every == 0 || k == nsteps)) bad = diverged(s, sp->blowup);
      if (bad) {
        out->stable = 0;
        out->t_fail = (double)k * sp->dt;
        break;
      }
      if (sample && k % every == 0) {
        size_t j = k / every;
        memcpy(out->traj.x + j * 3 * s->n, s->x, 3 * s->n * sizeof(double));
        if (sp->observe) sp->observe(s, (double)k * sp->dt, out->traj.extra + j * sp->nextra, sp->ctx);
      }
    }
    if (r == 0) {
      out->steps = nst;
      out->evals_per_step = nst ? (double)(s->evals - evals0) / (double)nst : NAN;
    }
    spent += total * 1e-6;
    /* Repeats are for noise on short runs; a run of half a second or more
     * is its own median over many steps. */
    if (!out->stable || spent > 0.5) {
      reps = r + 1;
      break;
    }
  }
  vstats_summary_t st = vstats_summarise(step_us, nst);
  out->step_us_median = st.median;
  out->step_us_p95 = st.p95;
  /* Cost per simulated second from the median step, not the total: on a
   * shared machine a few preempted steps would otherwise dominate it. */
  out->wall_per_sim_s = st.median * 1e-6 / sp->dt;
  free(step_us);
  return 0;
}

double ex_error(const traj_t *a, const traj_t *ref, const double *mass, double scale, double *end) {
  if (end) *end = NAN;
  if (!a || !ref || a->n != ref->n || a->ns != ref->ns || !a->x || !ref->x) return NAN;
  double msum = 0;
  for (size_t i = 0; i < a->n; i++) msum += mass ? mass[i] : 1.0;
  double worst = 0, last = NAN;
  for (size_t j = 0; j < a->ns; j++) {
    const double *p = a->x + j * 3 * a->n, *q = ref->x + j * 3 * a->n;
    double s = 0;
    for (size_t i = 0; i < a->n; i++) {
      double d0 = p[3 * i] - q[3 * i], d1 = p[3 * i + 1] - q[3 * i + 1], d2 = p[3 * i + 2] - q[3 * i + 2];
      s += (mass ? mass[i] : 1.0) * (d0 * d0 + d1 * d1 + d2 * d2);
    }
    last = sqrt(s / msum) / scale;
    if (!(last <= worst)) worst = last; /* NaN propagates */
  }
  if (end) *end = last;
  return worst;
}

double bbox_diag(const double *x, size_t n) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < n; i++)
    for (int k = 0; k < 3; k++) lo[k] = fmin(lo[k], x[3 * i + k]), hi[k] = fmax(hi[k], x[3 * i + k]);
  return sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

/* ---- context helpers ------------------------------------------------------------------ */

void nb_progress(const char *fmt, ...) {
  static uint64_t t0;
  if (!t0) t0 = vtime_mono_ns();
  va_list ap;
  va_start(ap, fmt);
  fprintf(stderr, "bench_numerics [%6.1f s]: ", (double)(vtime_mono_ns() - t0) * 1e-9);
  vfprintf(stderr, fmt, ap);
  fputc('\n', stderr);
  va_end(ap);
}

void nb_skip(nb_t *nb, const char *fmt, ...) {
  if (nb->nskipped >= (int)(sizeof nb->skipped / sizeof nb->skipped[0])) return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(nb->skipped[nb->nskipped], sizeof nb->skipped[0], fmt, ap);
  va_end(ap);
  nb_progress("skipped: %s", nb->skipped[nb->nskipped]);
  nb->nskipped++;
}

void nb_target(nb_t *nb, const char *fmt, ...) {
  if (nb->ntargets >= (int)(sizeof nb->targets / sizeof nb->targets[0])) return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(nb->targets[nb->ntargets++], sizeof nb->targets[0], fmt, ap);
  va_end(ap);
}

void nb_add_row(nb_t *nb, const nb_row_t *r) {
  if (nb->nrows == nb->caprows) {
    size_t cap = nb->caprows ? 2 * nb->caprows : 64;
    nb_row_t *g = realloc(nb->rows, cap * sizeof *g);
    if (!g) return;
    nb->rows = g;
    nb->caprows = cap;
  }
  nb->rows[nb->nrows++] = *r;
}

void nb_result(nb_t *nb, const char *scene, const char *model, const char *integ, double dt, int substeps,
               int iterations, const char *metric, double err, double err_end, const run_out_t *o) {
  nb_row_t r;
  memset(&r, 0, sizeof r);
  snprintf(r.scene, sizeof r.scene, "%s", scene);
  snprintf(r.model, sizeof r.model, "%s", model);
  snprintf(r.integ, sizeof r.integ, "%s", integ);
  int len = snprintf(r.setting, sizeof r.setting, "dt=1/%.0f", 1 / dt);
  if (substeps > 1 && len > 0 && (size_t)len < sizeof r.setting)
    len += snprintf(r.setting + len, sizeof r.setting - (size_t)len, " %d sub", substeps);
  if (iterations > 1 && len > 0 && (size_t)len < sizeof r.setting)
    snprintf(r.setting + len, sizeof r.setting - (size_t)len, " %d it", iterations);
  snprintf(r.metric, sizeof r.metric, "%s", metric);
  r.dt = dt;
  r.substeps = substeps;
  r.iterations = iterations;
  r.err = o->stable ? err : NAN;
  r.err_end = o->stable ? err_end : NAN;
  r.step_us = o->stable ? o->step_us_median : NAN;
  r.sim_ms = o->stable ? o->wall_per_sim_s * 1e3 : NAN;
  nb_add_row(nb, &r);
}

FILE *nb_csv(nb_t *nb, const char *name, const char *header) {
  char path[1200];
  snprintf(path, sizeof path, "%s/%s", nb->out, name);
  FILE *f = fopen(path, "w");
  if (!f) {
    nb_progress("cannot write %s", path);
    return NULL;
  }
  fprintf(f, "%s\n", header);
  nb_progress("writing %s", path);
  return f;
}

void nb_plot(nb_t *nb, plot_t *p, const char *name) {
  char path[1200];
  snprintf(path, sizeof path, "%s/%s", nb->out, name);
  verr_t err;
  if (plot_write_png(p, path, &err)) nb_progress("plot not written: %s", err.msg);
  else {
    nb->nplots++;
    nb_progress("wrote %s", path);
  }
}

double nb_dt(int k) { return 1.0 / (30.0 * (double)(1u << k)); }

const char *integ_label(integrator_kind_t k) {
  switch (k) {
  case INT_EXPLICIT_EULER: return "explicit Euler";
  case INT_SYMPLECTIC_EULER: return "symplectic Euler";
  case INT_VERLET: return "Verlet";
  case INT_RK4: return "RK4";
  case INT_IMPLICIT_EULER: return "implicit Euler";
  case INT_IMPLICIT_PCG: return "implicit PCG (live)";
  default: return "?";
  }
}
