/* SPDX-License-Identifier: Apache-2.0 */
/* numerics: the benchmark of docs/numerics.md (error against run time, stability)
 * for every deformation model and integrator.
 *
 * Shared pieces: a uniform handle on anything that can be stepped (sim_t:
 * a force system with an integrator, a PBD/XPBD solver, or a scene model),
 * the run loop that samples trajectories and times every step, the error
 * measures of docs/numerics.md §3, CSV output and the summary table. The scenes live
 * in scene_*.c, one file per family; main.c runs them in order. */
#ifndef NUMERICS_H
#define NUMERICS_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "physics/force_system.h"
#include "physics/integrator.h"
#include "physics/model.h"
#ifdef NUMERICS_HAVE_PBD
#include "physics/pbd.h"
#endif
#include "verr.h"

struct run_out;
struct plot;

/* ---- run-wide context ----------------------------------------------------- */

typedef struct nb_row {
  char scene[8], model[24], integ[20], setting[40], metric[16];
  double dt;                /* scene step, s */
  int substeps, iterations;
  double err, err_end;      /* metric max over time, and at the end (NAN: unstable) */
  double step_us, sim_ms;   /* median wall per scene step; wall ms per simulated second */
} nb_row_t;

typedef struct nb {
  int quick;
  char out[1024];     /* output directory */
  char assets[1024];  /* assets/ of the source tree */
  nb_row_t *rows;
  size_t nrows, caprows;
  int nplots;         /* PNG files written */
  char skipped[32][200]; /* what was left out and why, printed at the end */
  int nskipped;
  int probe_lost;         /* S8 runs that lost the probe contact */
  char targets[24][240];  /* docs/numerics.md §7 figures measured on the way */
  int ntargets;
} nb_t;

void nb_progress(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
void nb_skip(nb_t *nb, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
void nb_target(nb_t *nb, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
void nb_add_row(nb_t *nb, const nb_row_t *r);
/* Adds the row of one run (err/err_end NAN when it was unstable). */
void nb_result(nb_t *nb, const char *scene, const char *model, const char *integ, double dt, int substeps,
               int iterations, const char *metric, double err, double err_end, const struct run_out *o);
/* Opens OUT/name for writing (and says so on stderr); NULL on failure. */
FILE *nb_csv(nb_t *nb, const char *name, const char *header);
/* Writes the plot to OUT/name; counts it. */
void nb_plot(nb_t *nb, struct plot *p, const char *name);

/* Scene steps of the dt sweep: 1/(30 2^k), so every step divides the 1/30 s
 * sampling interval and trajectories compare at identical instants. */
double nb_dt(int k);

/* ---- anything that steps ----------------------------------------------------- */

typedef struct sim sim_t;
struct sim {
  size_t n;
  double *x, *v;       /* live state, 3n */
  const double *mass;  /* n, for mass-weighted errors (NULL: equal) */
  int substeps, iterations;
  uint64_t evals;      /* force evaluations or constraint projections so far */
  int (*step)(sim_t *s, double h); /* 0, or -1 on a non-finite state */
  double (*energy)(sim_t *s);      /* NAN when the model defines none */
  void (*destroy)(sim_t *s);
  double *x_init, *v_init; /* the state runs start from */
  void *impl;
};

/* A force system stepped by one integrator in `substeps` equal sub-steps;
 * the sim counts force evaluations itself. `owner_free` (may be NULL)
 * releases whatever owns the force system when the sim is destroyed;
 * `energy` (may be NULL) comes from the owner. */
sim_t *sim_fs(force_system_t *fs, integrator_kind_t kind, int substeps, double cg_tol, int cg_max,
              double (*energy)(void *owner), void (*owner_free)(void *owner), void *owner, verr_t *err);
#ifdef NUMERICS_HAVE_PBD
/* Takes ownership of an initialised pbd_t (allocated with malloc). */
sim_t *sim_pbd(pbd_t *s, verr_t *err);
#endif
/* Wraps a scene model; the sim destroys it. */
sim_t *sim_model(model_t *m, verr_t *err);
void sim_reset(sim_t *s);   /* back to x_init, v_init */
void sim_capture(sim_t *s); /* current state becomes x_init, v_init */
void sim_destroy(sim_t *s);

/* ---- runs ------------------------------------------------------------------------- */

typedef struct traj {
  size_t n, ns;   /* nodes, samples */
  double *x;      /* ns x 3n */
  size_t nextra;
  double *extra;  /* ns x nextra, from the observer */
} traj_t;

typedef struct run_spec {
  double dt, T, sample_dt;
  int reps;              /* timing repetitions (their steps are pooled); the first run is sampled */
  double blowup;         /* m: a node this far from its start is a divergence */
  size_t nextra;
  /* Fills extra[nextra] at every sample (t in s); may be NULL. */
  void (*observe)(sim_t *s, double t, double *extra, void *ctx);
  /* Called before every scene step with its start time; may be NULL. */
  void (*before_step)(sim_t *s, double t, void *ctx);
  void *ctx;
} run_spec_t;

typedef struct run_out {
  int stable;              /* 0: non-finite or diverged at t_fail */
  double t_fail;
  traj_t traj;
  size_t steps;
  double wall_per_sim_s;   /* s of wall time per simulated s: median step x steps per s */
  double step_us_median, step_us_p95;
  double evals_per_step;
} run_out_t;

int run_sim(sim_t *s, const run_spec_t *spec, run_out_t *out, verr_t *err);
void run_out_free(run_out_t *o);

/* e_x at every common sample: mass-weighted RMS distance between the two
 * trajectories over `scale` (the bounding-box diagonal). Returns the max over
 * samples; *end gets the last one. NAN when either run failed. */
double ex_error(const traj_t *a, const traj_t *ref, const double *mass, double scale, double *end);
/* Bounding-box diagonal of 3n positions. */
double bbox_diag(const double *x, size_t n);

/* ---- scenes ------------------------------------------------------------------------- */
void scene_spring(nb_t *nb);    /* S1 + plot 2 + energy / period table */
void scene_chain(nb_t *nb);     /* S2 + plot 6 (energy over many steps) */
void scene_cloth(nb_t *nb);     /* S3 */
void scene_stability(nb_t *nb); /* plot 3 */
void scene_bar(nb_t *nb);       /* S4, S5, S6 + plots 1, 2, 4, 5 */
void scene_probe(nb_t *nb);     /* S8 */
void scene_ball(nb_t *nb);      /* S7 */
void scene_scaling(nb_t *nb);   /* plot 7 */
void scene_incision(nb_t *nb);  /* S9 */

const char *integ_label(integrator_kind_t k); /* "symplectic Euler" */

#endif
