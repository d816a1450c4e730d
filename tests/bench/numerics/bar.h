/* SPDX-License-Identifier: Apache-2.0 */
/* bar: the benchmark's cantilever bar (tet_mesh_box_grid) and the models
 * that run on it, shared by the bar scenes, the stability sweep and the
 * scaling plot.
 *
 * The bar is nx x ny x nz nodes at spacing h along x, the x = 0 face fixed.
 * Material: rubber-like, density 1000 kg/m^3 with equal lumped masses, edge
 * springs k (mass_spring_tet), and for XPBD the same edges as distance
 * constraints of compliance 1/k with the volume constraints made inactive
 * (compliance VOLUME_OFF): XPBD then solves the same spring network, so
 * both share one converged reference. PBD has no physical stiffness (0..1
 * per constraint); it runs with the scene defaults (1, 1). */
#ifndef NUMERICS_BAR_H
#define NUMERICS_BAR_H

#include <stddef.h>
#include <stdint.h>

#include "numerics.h"
#include "tet_mesh.h"

#define BAR_DENSITY 1000.0
#define BAR_VOLUME_OFF 1e3 /* m^6/J: alpha/h^2 so large the volume term does nothing */

typedef struct bar {
  size_t nx, ny, nz;
  double h;
  tet_mesh_t tm;
  size_t nedges;
  uint32_t *edges; /* 2 nedges, unique tet edges */
  double *edge_rest, *tet_rest;
  double mass;     /* kg, total */
  double diag;     /* m, rest bounding-box diagonal */
  size_t tip;      /* node at the centre of the free end (or its nearest) */
} bar_t;

int bar_init(bar_t *b, size_t nx, size_t ny, size_t nz, double h, verr_t *err);
void bar_free(bar_t *b);

/* mass_spring_tet on the bar: springs k, no home springs, ground damping
 * c_ground (N s/m per node, the product's home_damping); x0 (may be NULL:
 * rest) is the initial state. */
sim_t *bar_mass_spring(const bar_t *b, integrator_kind_t kind, int substeps, double k, double c_ground,
                       const double g[3], const double *x0, double cg_tol, verr_t *err);
#ifdef NUMERICS_HAVE_PBD
/* PBD (xpbd = 0, stiffness 1) or XPBD (xpbd = 1, distance compliance 1/k,
 * volume off) with ground damping `damping` (N s/m per node). */
sim_t *bar_pbd(const bar_t *b, int xpbd, int substeps, int iterations, double k, double damping, const double g[3],
               const double *x0, verr_t *err);
#endif

/* The same models on any tetrahedral mesh (organ meshes from tet_mesh_build,
 * for timing), with the product's material defaults (scene.h): mass 0.1 kg,
 * edge springs 30 N/m with 0.02 N s/m, home springs 30 N/m with 0.005 N s/m;
 * XPBD with distance compliance 1e-4, volume compliance 1e-6. No fixed nodes. */
sim_t *tets_mass_spring(const tet_mesh_t *tm, integrator_kind_t kind, verr_t *err);
#ifdef NUMERICS_HAVE_PBD
sim_t *tets_xpbd(const tet_mesh_t *tm, int iterations, verr_t *err);
#endif

/* sqrt of the largest eigenvalue of M^-1 K of the spring network at rest
 * (mass_spring_eigen_bounds: power iteration), rad/s. */
double bar_omega_max(const bar_t *b, double k);

/* Geometry figures at positions x: smallest V/V0, number of tets with
 * V <= 0, largest |V/V0 - 1|, largest |L/L0 - 1|. */
void bar_measures(const bar_t *b, const double *x, double *min_ratio, double *inverted, double *worst_vol,
                  double *max_strain);

#endif
