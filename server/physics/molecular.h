/* SPDX-License-Identifier: Apache-2.0 */
/* molecular: the molecular modelling system (MMS) on a triangle surface
 * (docs/methods.md A §2.2, eq. 6-11; Sekercioglu and Duysak 2009).
 *
 * Vertices are atoms and every unique mesh edge is a bond; every triangle
 * has three bond angles (theta at corner j between bonds j-i and j-k). With
 * dr = r - r0 and dc = cos(theta) - cos(theta0) the potential is
 *
 *   E_bond  = sum_bonds  1/2 k_r dr^2                       (eq. 6, force eq. 8)
 *   E_angle = sum_angles 1/2 k_theta dc^2                    (eq. 9, cosine form)
 *   E_sb    = sum_angles k_sb dc (dr_a + dr_b)               (eq. 11; a, b the
 *                                                             angle's two bonds)
 *
 * and forces are its exact negative gradient (eq. 7), not the seed's
 * approximate direction of eq. 10. Per angle (its two bonds and its cosine)
 * the quadratic form [[k_r,0,k_sb],[0,k_r,k_sb],[k_sb,k_sb,k_theta]] has
 * determinant k_r (k_r k_theta - 2 k_sb^2), hence the parameter rule
 * k_r k_theta > 2 k_sb^2 (docs/numerics.md §6). On a mesh a bond is shared by up
 * to four angles, so this is the per-angle condition, not a proof for the
 * whole mesh (k_r k_theta >= 8 k_sb^2 is: see molecular_stiffness_mul);
 * power iteration on the rest Hessian of the tissue block and the spleen
 * found no negative eigenvalue down to k_r k_theta = 2.05 k_sb^2, and the
 * home springs add their margin. The cosine form's stiffness is
 * k_theta sin^2(theta0): angles resting near 0 or 180 degrees are soft.
 *
 * As in the mass-spring model (mass_spring.h) every vertex also has a home
 * spring to its rest position with ground damping, bonds carry Kelvin-Voigt
 * damping (the seed has none; the material's edge damping keeps the model
 * comparable to mass-spring), masses are equal and lumped, gravity acts and
 * vertices can be fixed.
 *
 * Degeneracies (docs/numerics.md case 13): every length is regularised,
 * r = sqrt(|d|^2 + eps^2) with eps = 1e-4 x the mean rest edge, and the
 * rest lengths and cos(theta0) use the same measure. The energy is then
 * smooth everywhere and the forces are its exact gradient: a zero-length bond
 * pushes nothing, the cosine's gradient is bounded by 2 / eps, and angles of
 * 0 or 180 degrees or zero-area triangles need no special case (no acos, no
 * division by sin). The change to the published energy (docs/methods.md A) is below (eps / r)^2.
 *
 * Not thread-safe: one physics thread owns a model. Allocation happens in
 * molecular_create only. */
#ifndef VISCERA_MOLECULAR_H
#define VISCERA_MOLECULAR_H

#include <stddef.h>
#include <stdint.h>

#include "mesh.h"
#include "physics/force_system.h"
#include "verr.h"

typedef struct mol_params {
  double mass;           /* kg, total, spread equally over vertices */
  double bond_k;         /* k_r, N/m */
  double angle_k;        /* k_theta, J */
  double stretch_bend_k; /* k_sb, N */
  double bond_damping;   /* N s/m along each bond */
  double home_stiffness; /* N/m per vertex */
  double home_damping;   /* N s/m per vertex */
  double gravity[3];     /* m/s^2 */
} mol_params_t;

typedef struct mol_bond {
  uint32_t i, j;
  double r0; /* regularised rest length */
} mol_bond_t;

/* One triangle's angle terms. Edge e joins corner e to corner e+1 (mod 3);
 * c0[k] is the rest cosine at corner k. Every bond is also evaluated in
 * the first triangle that has it (bit e of `owns`), so the force loop visits
 * each edge length once per triangle and needs no separate bond pass. */
typedef struct mol_tri {
  uint32_t v[3];
  uint32_t owns;
  double r0[3];
  double c0[3];
} mol_tri_t;

typedef struct molecular {
  size_t n, nbonds, ntris;
  mol_params_t p;          /* may be changed between steps (tests switch terms off) */
  double eps2;             /* length regularisation eps^2, m^2 */
  double *x, *v;           /* 3n, current state */
  double *x_rest;          /* 3n */
  double *f_ext;           /* 3n, external forces of the current sub-step */
  double *mass, *inv_mass; /* n; inv_mass 0 = fixed */
  mol_bond_t *bonds;
  mol_tri_t *tris;
  uint32_t *tri_idx;     /* 3 ntris, the surface's triangles */
  force_system_t fs;     /* forces + stiffness_mul on x, v; ctx = this */
  void *user;            /* free for the owner (the model wrapper) */
  int definite_jacobian; /* see molecular_stiffness_mul; 0 after create */
} molecular_t;

/* 0 if the set gives a positive-definite per-angle energy: all finite,
 * k_r > 0, k_theta > 0 and k_r k_theta > 2 k_sb^2; otherwise -1 with the
 * numbers in err. */
int molecular_check_params(double k_r, double k_theta, double k_sb, verr_t *err);

/* Builds bonds from the unique edges, the angle terms from the triangles and
 * equal lumped masses; refuses bad parameters (molecular_check_params),
 * a zero-area mesh and OOM. The force system in m->fs is ready for
 * integrator.h (pre_substep NULL). */
int molecular_create(molecular_t *m, const mesh_t *surface, const mol_params_t *p, verr_t *err);
void molecular_destroy(molecular_t *m);

/* Fixes every vertex whose rest z is below z. Returns how many. */
size_t molecular_fix_below(molecular_t *m, double z);

/* f = all forces at (x, v): bonds, angles, stretch-bend, bond damping, home
 * springs, ground damping, gravity, f_ext. Fixed vertices get forces too
 * (the integrators ignore them). */
void molecular_forces(const molecular_t *m, const double *x, const double *v, double *f);

/* out = (a K(x) + b C) y. K = exact Hessian of the potential (bond, angle,
 * stretch-bend, home), computed analytically as the directional derivative
 * of the gradient along y; it includes the curvature terms, so it can be
 * indefinite away from rest (compressed bonds, angles pushed past their
 * rest cosine). C = home damping I + bond damping u u^T. The bond damping's
 * dependence on x through u is left out of K (the usual linearisation; it
 * keeps K symmetric for conjugate gradients).
 *
 * With definite_jacobian set, K is the Gauss-Newton part: the curvature
 * terms are dropped, leaving J^T Q J with J the gradients of the bond
 * lengths and angle cosines and Q the quadratic form of eq. 6, 9, 11 over
 * them; exact at rest. Q is positive semi-definite when k_r k_theta >=
 * k_sb^2 lambda_max(S S^T), S the bond-angle incidence, whose rows sum to 8
 * for an interior edge of a manifold mesh (in four angles): k_r k_theta >=
 * 8 k_sb^2 makes it definite for every mesh state, and k_sb = 0 (the
 * default) always does. */
void molecular_stiffness_mul(const molecular_t *m, const double *x, double a, double b, const double *y, double *out);

/* implicit_pcg's right-hand side (force_system_t.linearize): rhs = h F(x,
 * v) - h^2 K v at the current state, K the Gauss-Newton part (as with
 * definite_jacobian), in one pass over the triangles instead of a force
 * pass and a product pass. */
void molecular_linear_rhs(const molecular_t *m, double h, double *rhs);

/* Potential energy (bond, angle, stretch-bend, home, gravity) at x, J. */
double molecular_potential(const molecular_t *m, const double *x);
/* Kinetic + potential at the current state, J. */
double molecular_energy(const molecular_t *m);

/* Largest eigenvalues of M^-1 K and M^-1 C at rest over the free vertices
 * (power iteration, +2 % for the unconverged remainder). extra_home (N/m) is
 * added to every vertex's home spring for the bound only (tool springs).
 * Uses scratch of 6n doubles it allocates; returns -1 on OOM. */
int molecular_rest_lambdas(const molecular_t *m, double extra_home, double *lambda_k, double *lambda_c);

/* Largest |r/r0 - 1| over bonds. */
double molecular_max_strain(const molecular_t *m);

#endif
