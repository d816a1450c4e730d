/* SPDX-License-Identifier: Apache-2.0 */
/* mass_spring: mass-spring forces as a force_system_t (docs/methods.md B §4.2.3,
 * §5.2.4; docs/methods.md A eq. 1-5), for the integrators in integrator.h.
 *
 * Springs are the unique edges of a triangle surface (surface variant) or of
 * a tetrahedral mesh (volume variant). Every spring has Kelvin-Voigt damping
 * (docs/methods.md B eq. 5.3): the force on i is f = k (L - L0) u + c ((v_j - v_i) . u) u
 * with u the unit vector from i to j. Every node also has a home spring to
 * its rest position with ground damping (the surrounding tissue holding the
 * organ's shape), and gravity acts on the lumped masses, which are equal
 * (total / nodes: area or volume weighting would give the tiny elements of
 * real meshes tiny masses and with them a much smaller stable step). Nodes
 * can be fixed (inverse mass 0).
 *
 * Jacobians (stiffness_mul). K = -dF/dx is exact for the conservative forces:
 * per spring k [u u^T + (1 - L0/L)(I - u u^T)] (the second part is the
 * geometric term), plus home_stiffness I. C = -dF/dv is exact: c u u^T per
 * spring plus home_damping I. The damping force also turns with u, a
 * dependence on x that needs v and is not symmetric; it is left out of K,
 * as is usual for the implicit solve (it vanishes at v = 0). A compressed
 * spring (L < L0) has a negative geometric term and can make K indefinite,
 * which conjugate gradients cannot solve: with `definite_jacobian` set,
 * stiffness_mul clamps (1 - L0/L) at 0, the standard positive semi-definite
 * approximation (exact for stretched springs).
 *
 * Arrays are allocated once in mass_spring_create_*; forces, stiffness_mul,
 * energy and strain allocate nothing. Not thread-safe: one physics thread
 * owns the object.
 *
 * Spring order: forces and stiffness_mul are fastest when springs sharing
 * node i are consecutive, as built (sorted by (i, j), also after cutting's
 * set_surface_topology); they are correct for any order (a shuffled array
 * gives the same forces to rounding, only slower). */
#ifndef VISCERA_MASS_SPRING_H
#define VISCERA_MASS_SPRING_H

#include <stddef.h>
#include <stdint.h>

#include "mesh.h"
#include "physics/force_system.h"
#include "tet_mesh.h"
#include "verr.h"

typedef struct ms_params {
  double mass;           /* kg, total */
  double stiffness;      /* N/m per edge spring */
  double damping;        /* N s/m per edge spring */
  double home_stiffness; /* N/m per node */
  double home_damping;   /* N s/m per node */
  double gravity[3];     /* m/s^2 */
} ms_params_t;

typedef struct ms_spring {
  uint32_t i, j;
  double rest;
} ms_spring_t;

typedef struct mass_spring {
  force_system_t fs; /* first member; x, v, mass, inv_mass point into this object. ctx and
                      * pre_substep are left NULL for the owner (the model) to set */
  size_t n;          /* nodes */
  size_t nsprings;
  ms_params_t p;
  double *x, *v;    /* 3n, current state */
  double *x_rest;   /* 3n, home positions */
  double *f_ext;    /* 3n, external forces, included by forces() until cleared */
  double *mass;     /* n */
  double *inv_mass; /* n, 0 for fixed nodes */
  ms_spring_t *springs;
  int definite_jacobian; /* see above; 0 after create */
  /* Factor on the edge dampers in forces() (1 after create; the Jacobian
   * products and energies ignore it). An explicit scheme whose sub-step h
   * would make h lambda_c large caps the dampers' rate in the stiffest
   * modes with it (model_mass_spring.c), instead of taking more sub-steps. */
  double damping_scale;
  /* Optional per-spring stiffness factor (nsprings, indexed like springs):
   * spring s has stiffness p.stiffness * k_scale[s]; damping stays uniform.
   * NULL (the default) means 1 for every spring and costs nothing. Set only
   * through mass_spring_set_stiffness_scale; owned by this object. Code that
   * adds or removes springs must keep it in step (or clear it). */
  double *k_scale;
  /* Cutting (server/cutting/ms_cut.h) only; NULL / 0 until a cut happens. */
  double *f_res; /* 3n or NULL: constant nodal forces (residual stress, docs/methods.md D eq. 4), in forces() and
                    potential() */
  size_t cap;    /* node capacity of the node arrays (>= n) */
  /* The AVX2 force loop's gather index (mass_spring.c): for every node, the
   * springs that act on it in the order the scalar loop adds them, built
   * from the springs by whatever builds them (and by
   * mass_spring_springs_changed); used only while springs, nsprings and
   * the node range still match what it was built for. g: scratch, 4
   * doubles per spring. NULL members: no index (the scatter loop runs). */
  struct ms_gather {
    const ms_spring_t *springs;
    size_t nsprings, nv; /* nv: 1 + the largest node index of a spring */
    uint32_t *off, *ev;  /* nv + 1 offsets into ev */
    double *g;
  } gather;
} mass_spring_t;

/* Springs from the unique edges of the triangles of `surface` (nodes = its
 * vertices). Returns 0, or -1 with err (bad parameters, OOM, zero area). */
int mass_spring_create_surface(mass_spring_t *ms, const mesh_t *surface, const ms_params_t *p, verr_t *err);
/* Springs from the unique edges of the tetrahedra of `t` (nodes = its nodes). */
int mass_spring_create_tets(mass_spring_t *ms, const tet_mesh_t *t, const ms_params_t *p, verr_t *err);
void mass_spring_destroy(mass_spring_t *ms);

/* Copies `scale` (nsprings factors, finite, >= 0, indexed like springs) into
 * k_scale; NULL clears it (uniform stiffness again). Returns 0, or -1 with
 * err (bad factor, OOM). Construction time: it allocates. */
int mass_spring_set_stiffness_scale(mass_spring_t *ms, const double *scale, verr_t *err);
/* Topology changes (cutting). reserve grows every node array to cap nodes
 * (contents kept, fs pointers updated; with_f_res also allocates f_res,
 * zeroed); it allocates only when cap exceeds the capacity. After the caller
 * has written n <= cap nodes (x, v, x_rest, mass, inv_mass, f_res),
 * set_surface_topology rebuilds the springs from the unique edges of tris
 * (rest lengths from x_rest), sets n and p.mass (the sum of the masses).
 * Both return 0, or -1 with err (OOM, index out of range); on error the
 * springs are left as they were. */
int mass_spring_reserve(mass_spring_t *ms, size_t cap, int with_f_res, verr_t *err);
int mass_spring_set_surface_topology(mass_spring_t *ms, size_t n, const uint32_t *tris, size_t ntris, verr_t *err);

/* Fixes every node whose rest z is below z (zero inverse mass). Returns how many. */
size_t mass_spring_fix_below(mass_spring_t *ms, double z);

/* f = F(x, v): edge springs and dampers, home springs and dampers, gravity,
 * f_res and f_ext. Forces stay finite for coincident nodes (a zero-length spring
 * has no direction and pushes nothing). */
void mass_spring_forces(const mass_spring_t *ms, const double *x, const double *v, double *f);
/* The same through a chosen spring loop: simd 1 the AVX2 gather loop (the
 * scatter one without a gather index), 2 the AVX2 scatter loop, 0 the
 * scalar loop; without AVX2 in the processor always the scalar one. All
 * give the same forces bit for bit (same operations in the same order per
 * component, no fused multiply-add); mass_spring_forces takes simd 1
 * whenever mass_spring_simd_available() (checked at run time, the build
 * needs no -mavx2). For the tests and benchmarks that compare them. */
void mass_spring_forces_path(const mass_spring_t *ms, const double *x, const double *v, double *f, int simd);
int mass_spring_simd_available(void);
/* The active set of physics/ms_regions.h: pass 1 of the gather loop (each
 * spring's force row) only over the blocks of four springs (4b .. 4b + 3)
 * whose bit b is set in blk, pass 2 (node terms and the sum of the rows)
 * only over the nodes whose bit is set in nodes (64 per word, bit k % 64 of
 * word k / 64); f is written at those nodes only. Rows of the other blocks
 * are kept from when they were last evaluated: the caller marks every block
 * whose springs' ends may have changed since. A node whose springs' blocks
 * are all marked gets mass_spring_forces' value bit for bit. Without
 * mass_spring_subset_available (no AVX2, no gather index) it is
 * mass_spring_forces (every node written). */
int mass_spring_subset_available(const mass_spring_t *ms);
void mass_spring_forces_subset(const mass_spring_t *ms, const double *x, const double *v, double *f,
                               const uint64_t *blk, const uint64_t *nodes);
/* Code that rewrites springs[] in place (order, ends) calls this after, so
 * the AVX2 loop's gather index follows (it allocates; on OOM the AVX2 loop
 * falls back to scattering, same forces). Whatever replaces the array
 * through mass_spring_create_* / set_surface_topology needs no call. */
void mass_spring_springs_changed(mass_spring_t *ms);

/* out = (a K(x) + b C(x)) y, as described above. */
void mass_spring_stiffness_mul(const mass_spring_t *ms, const double *x, double a, double b, const double *y,
                               double *out);

/* Largest eigenvalues of M^-1 K and M^-1 C at the rest state over the free
 * nodes, with extra_home_k (N/m) added to every node's home spring (the
 * stiffest tool spring that may touch it). Power iteration with the
 * M-weighted Rayleigh quotient, scaled up 2 % for the unconverged remainder
 * and capped by the block-Gershgorin bound max_i (2 sum_j k_ij + k_home) / m_i,
 * which can never be exceeded. Allocates scratch (construction time only).
 * Returns 0, or -1 on OOM. */
int mass_spring_eigen_bounds(const mass_spring_t *ms, double extra_home_k, double *lambda_k, double *lambda_c);

/* The same with caller-kept vectors vk, vc (3n each): the start vectors
 * when warm (a topology change keeps most of the dominant modes, so the
 * iteration converges in a fraction of the steps; it stops when the
 * estimate changes by less than 1e-5 between iterations instead of 1e-7),
 * the dominant vectors on return. With equal masses lambda_c is derived
 * from lambda_k (same dominant vector at rest; vc is then untouched),
 * halving the cost. warm = 0 starts from the same vector as mass_spring_eigen_bounds
 * and gives the same lambda_k. Returns 0, or -1 on OOM. */
int mass_spring_eigen_bounds_warm(const mass_spring_t *ms, double extra_home_k, double *vk, double *vc, int warm,
                                  double *lambda_k, double *lambda_c);

/* Resumable power iteration on M^-1 K at rest (+ extra_home_k I), for a
 * re-estimate spread over several steps: up to `iterations` iterations from
 * x (scratch y, 3n each); *count and *lambda (the last Rayleigh quotient)
 * carry the state between calls. Returns 1 when converged (after 21
 * iterations, change <= 1e-5) or after 500, else 0. */
int mass_spring_power_steps(const mass_spring_t *ms, double extra_home_k, double *x, double *y, int iterations,
                            int *count, double *lambda);
/* Block-Gershgorin bound of M^-1 K at rest (no eigenvalue exceeds it); with
 * first_new < n only over the springs touching nodes >= first_new and
 * those nodes' home springs. scratch: n doubles. */
double mass_spring_gershgorin(const mass_spring_t *ms, double extra_home_k, size_t first_new, double *scratch);
/* lambda of M^-1 C from lambda of M^-1 K when all free nodes have the same
 * mass (see mass_spring_eigen_bounds_warm); NAN otherwise. */
double mass_spring_lambda_c_from_k(const mass_spring_t *ms, double extra_home_k, double lambda_k);

/* Adds an external force (N) at node i; forces() includes it until cleared. */
static inline void mass_spring_add_force(mass_spring_t *ms, uint32_t i, const double f[3]) {
  ms->f_ext[3 * i] += f[0];
  ms->f_ext[3 * i + 1] += f[1];
  ms->f_ext[3 * i + 2] += f[2];
}

/* Kinetic + elastic (edge and home springs) + gravitational potential
 * energy, J; f_ext does no bookkeeping here. */
double mass_spring_energy(const mass_spring_t *ms);
/* Potential energy at positions x: edge and home springs, gravity and the
 * constant forces f_res, so that F(x, 0) = -grad U(x) + f_ext. */
double mass_spring_potential(const mass_spring_t *ms, const double *x);
/* Largest |L/L0 - 1| over springs with L0 > 0: the live strain figure. */
double mass_spring_max_strain(const mass_spring_t *ms);

#endif
