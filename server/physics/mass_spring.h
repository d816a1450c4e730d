/* mass_spring: mass-spring model on a triangle surface (seed 002 §4.2.3, §5.2.4;
 * seed 000 eq. 1-5).
 *
 * Every unique mesh edge is a spring with Kelvin-Voigt damping (seed 002 eq.
 * 5.3): f = k (L - L0) u + c ((v_j - v_i) . u) u. Every vertex also has a home
 * spring to its rest position with ground damping, which preserves the organ's
 * shape. Masses are lumped and equal (total / vertices). Vertices can be fixed.
 *
 * State is structure-of-arrays, allocated once in mass_spring_create; stepping
 * allocates nothing. Not thread-safe: one physics thread owns a model. */
#ifndef VISCERA_MASS_SPRING_H
#define VISCERA_MASS_SPRING_H

#include <stddef.h>
#include <stdint.h>

#include "mesh.h"
#include "verr.h"

typedef enum ms_integrator {
  MS_SYMPLECTIC_EULER, /* v += h a(x, v); x += h v   (stable for h^2 l_k + 2 h l_c < 4) */
  MS_EXPLICIT_EULER    /* x += h v; v += h a(x, v)   (unstable undamped at any h) */
} ms_integrator_t;

typedef struct ms_params {
  double mass;           /* kg, total */
  double stiffness;      /* N/m per edge spring */
  double damping;        /* N s/m per edge spring */
  double home_stiffness; /* N/m per vertex */
  double home_damping;   /* N s/m per vertex */
  double gravity[3];     /* m/s^2 */
  ms_integrator_t integrator;
} ms_params_t;

typedef struct ms_spring {
  uint32_t i, j;
  double rest;
} ms_spring_t;

typedef struct mass_spring {
  size_t n;            /* vertices */
  size_t nsprings;
  ms_params_t p;
  double *x, *v;       /* 3n, current state */
  double *x_rest;      /* 3n, home positions */
  double *f;           /* 3n, force scratch */
  double *f_ext;       /* 3n, external forces for the next step (cleared by step) */
  double *inv_mass;    /* n, 0 for fixed vertices */
  double *mass;        /* n */
  double *x_prev, *v_prev; /* 3n, last good state for rollback */
  ms_spring_t *springs;
} mass_spring_t;

/* Builds springs from the unique edges of `surface` and lumps masses.
 * Returns 0, or -1 with err (bad parameters, OOM, zero-area mesh). */
int mass_spring_create(mass_spring_t *ms, const mesh_t *surface, const ms_params_t *p, verr_t *err);
void mass_spring_destroy(mass_spring_t *ms);

/* Fixes every vertex whose rest z is below z (zero inverse mass). Returns how many. */
size_t mass_spring_fix_below(mass_spring_t *ms, double z);

/* Largest step h for which the chosen integrator stays stable: with l_k and
 * l_c the largest eigenvalues of M^-1 K and M^-1 C at rest (power
 * iteration), symplectic Euler needs h^2 l_k + 2 h l_c < 4. Explicit Euler
 * has no bound for undamped systems: returns the damped bound
 * h <= 2 zeta / omega = l_c / l_k, which may be 0. Allocates scratch. */
double mass_spring_stable_dt(const mass_spring_t *ms);

/* Accumulates internal + home + gravity + f_ext forces for state (x, v) into f. */
void mass_spring_forces(const mass_spring_t *ms, const double *x, const double *v, double *f);

/* Adds an external force (N) at vertex i for the next step. */
static inline void mass_spring_add_force(mass_spring_t *ms, uint32_t i, const double f[3]) {
  ms->f_ext[3 * i] += f[0];
  ms->f_ext[3 * i + 1] += f[1];
  ms->f_ext[3 * i + 2] += f[2];
}

/* Called before each sub-step's force evaluation, so stiff couplings (the
 * haptic proxy spring) are re-evaluated at the sub-step rate; it may add to
 * f_ext, which is cleared after every sub-step. */
typedef void (*ms_substep_fn)(mass_spring_t *ms, void *ctx);

/* Advances by h with `substeps` equal sub-steps (pre may be NULL). If any
 * coordinate becomes non-finite, restores the state from before the call and
 * returns -1 (the step is rolled back); otherwise 0. */
int mass_spring_step(mass_spring_t *ms, double h, int substeps, ms_substep_fn pre, void *ctx);

/* Kinetic + elastic (edge and home springs) energy, J. */
double mass_spring_energy(const mass_spring_t *ms);
/* Largest |L/L0 - 1| over springs: the live strain figure. */
double mass_spring_max_strain(const mass_spring_t *ms);

#endif
