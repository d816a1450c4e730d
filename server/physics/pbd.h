/* SPDX-License-Identifier: Apache-2.0 */
/* pbd: position based dynamics on a tetrahedral mesh (docs/methods.md C §4; Müller
 * et al. 2007 for PBD, Macklin et al. 2016 for XPBD).
 *
 * Constraints (docs/methods.md C §4.4, §4.5):
 *   - distance, one per unique tetrahedron edge:  C = |x_i - x_j| - d,
 *     grad_i C = n, grad_j C = -n, n = (x_i - x_j) / |x_i - x_j|;
 *   - volume, one per tetrahedron:  C = 6 (V - V0) with
 *     6 V = (x1 - x0) x (x2 - x0) . (x3 - x0), so
 *     grad_1 = (x2 - x0) x (x3 - x0), grad_2 = (x3 - x0) x (x1 - x0),
 *     grad_3 = (x1 - x0) x (x2 - x0), grad_0 = -(grad_1 + grad_2 + grad_3).
 *     V is signed, so an inverted tetrahedron (V < 0) has C < -6 V0 and the
 *     gradient, the normal of the opposite face, still points towards
 *     positive volume: inverted elements are pushed back through zero;
 *   - home (optional), per node and axis, a zero-length spring of stiffness
 *     home_stiffness (N/m) to the rest position: the surrounding tissue that
 *     keeps an organ in its place. Always compliant (alpha = 1 / k), in PBD
 *     mode too, because its stiffness is a physical N/m.
 *
 * One sub-step of length h (Gauss-Seidel, in place):
 *   v = v / (1 + h c w) + h (g + w f_ext)   (ground damping c, implicit);
 *   x_old = x; x += h v;  lambda = 0;
 *   repeat `iterations` times: project every distance, volume, home constraint;
 *   v = (x - x_old) / h.
 * PBD: dlambda = -k' C / sum w |grad C|^2 with k in 0..1 per constraint type;
 *   with stiffness_correction k' = 1 - (1 - k)^(1/iterations) (Müller 2007
 *   §3.3) so that after all iterations a lone constraint's error shrinks by
 *   the factor 1 - k whatever the iteration count. Effective stiffness still
 *   depends on iterations and h (the cantilever sags less with more).
 * XPBD: dlambda = (-C - alpha~ lambda) / (sum w |grad C|^2 + alpha~),
 *   alpha~ = alpha / h^2, lambda accumulated per constraint and reset every
 *   sub-step; lambda / h^2 is the constraint force (N for distance).
 * Tool springs (optional, `cpl`, PBD and XPBD alike): the springs the
 *   sub-step's hook declared act as its explicit force in the prediction,
 *   and their stiffness is taken implicitly after the iterations: the
 *   velocity v = (x - x_old) / h takes coupling.h's rank-one solve
 *   (v' = v - h^2 k M^-1 w b^T v' per spring) and the nodes it moved take
 *   x = x_old + h v'. At rest (v = 0) nothing changes, so the force at a
 *   dent is the penalty form's exactly; a stiff tool no longer feeds back
 *   through a whole sub-step explicitly. (A compliant constraint inside the
 *   iterations, alpha = 1 / k, was measured too and not kept: at the scene's
 *   few iterations its static force fell 1.4-3.5 % short of the penalty's
 *   at 400 N/m and 30 % at 4,000 N/m; docs/numerics.md.)
 *
 * Masses are lumped and equal (total / nodes) unless set per node; fixed
 * nodes have inverse mass 0. State is structure-of-arrays, allocated once in
 * pbd_create; stepping allocates nothing. Not thread-safe. */
#ifndef VISCERA_PBD_H
#define VISCERA_PBD_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "physics/coupling.h"
#include "physics/model.h"
#include "physics/model_guard.h"
#include "verr.h"

/* Constraints are ordered by colour, at most this many (see pbd.c). */
#define PBD_COLOURS 128

typedef enum pbd_mode { PBD_MODE_PBD, PBD_MODE_XPBD } pbd_mode_t;

typedef struct pbd_params {
  pbd_mode_t mode;
  double mass;                /* kg, total, spread evenly over the nodes */
  double distance_stiffness;  /* PBD, 0..1 */
  double volume_stiffness;    /* PBD, 0..1 */
  double distance_compliance; /* XPBD, m/N (>= 0; 0 = rigid) */
  double volume_compliance;   /* XPBD, per C = 6 (V - V0): m^6/J (>= 0) */
  double home_stiffness;      /* N/m per node to its rest position, 0 = free body */
  double damping;             /* N s/m per node, relative to the ground */
  double gravity[3];          /* m/s^2 */
  int substeps;               /* >= 1 */
  int iterations;             /* >= 1, per sub-step */
  int stiffness_correction;   /* PBD: use k' = 1 - (1 - k)^(1/iterations) */
} pbd_params_t;

typedef struct pbd {
  pbd_params_t p;
  size_t n, nedges, ntets;
  double *x, *v, *x_rest;  /* 3n */
  double *x_old;           /* 3n, positions at the start of the sub-step */
  model_guard_t guard;     /* state before the step, for rollback (physics/model_guard.h) */
  double *f_ext;           /* 3n, external forces for the current sub-step */
  double *inv_mass, *mass; /* n */
  uint32_t *edge;          /* 2 nedges, i < j, in colour order */
  double *edge_rest;       /* nedges, rest length */
  double *edge_lambda;     /* nedges */
  uint32_t *tet;           /* 4 ntets, in colour order */
  double *tet_rest;        /* ntets, rest volume V0 (> 0 for a valid mesh) */
  double *tet_step2;       /* ntets, squared largest node move per volume projection (see pbd.c) */
  double *tet_lambda;      /* ntets */
  double *home_lambda;     /* 3n */
  uint8_t *mark;           /* n, scratch for pbd_constraint_force */
  /* Caches of the inverse masses per constraint (see pbd.c). */
  double *tet_w;    /* 4 ntets */
  double *edge_w;   /* 2 nedges */
  double *edge_inv; /* nedges, 1 / (w_i + w_j + alpha~) for alpha~ = edge_inv_at */
  double edge_inv_at;
  int cache_stale; /* masses changed since the caches were filled */
  /* Colour c holds edges edge_colour[c] .. edge_colour[c + 1] - 1 (and
   * tetrahedra likewise), no two sharing a node, except the last colour,
   * which takes any overflow. */
  size_t edge_colour[PBD_COLOURS + 1], tet_colour[PBD_COLOURS + 1];
  int simd;           /* 1: four-wide volume sweep (AVX2 found at create); 0 forces the scalar loop */
  double rest_volume; /* sum of V0 */
  double last_h;      /* sub-step of the last step, for forces from lambda */
  uint64_t rollbacks;
  /* Optional per-edge factor on the distance compliance (nedges, indexed like
   * edge, i.e. in colour order): edge e has compliance
   * p.distance_compliance * edge_alpha_scale[e] (0: rigid). XPBD only (PBD
   * mode has no compliance). NULL (the default) means 1 for every edge and
   * keeps the four-wide sweeps; set, the distance sweep runs scalar. Set
   * through pbd_set_edge_compliance_scale; owned by this object. */
  double *edge_alpha_scale;
  /* Tool springs of the current sub-step, filled by the pre hook (NULL or
   * empty: none); not owned (model_pbd.c holds it). */
  coupling_set_t *cpl;
} pbd_t;

/* Called before each sub-step (contact coupling); may add to f_ext, which is
 * cleared after every sub-step. */
typedef void (*pbd_substep_fn)(pbd_t *s, void *ctx);

/* Builds constraints from the unique edges and the tetrahedra of the mesh
 * (x: 3 nnodes rest positions, tets: 4 ntets, positively oriented). Returns
 * 0, or -1 with err (bad parameters, out-of-range index, OOM). */
int pbd_create(pbd_t *s, size_t nnodes, const double *x, size_t ntets, const uint32_t *tets, const pbd_params_t *p,
               verr_t *err);
/* Distance constraints only, one per unique (i, j) pair of `edges` (2
 * nedges node indices), no volume constraints: chains, strings and other
 * networks that are not tetrahedral meshes. */
int pbd_create_edges(pbd_t *s, size_t nnodes, const double *x, size_t nedges, const uint32_t *edges,
                     const pbd_params_t *p, verr_t *err);
void pbd_destroy(pbd_t *s);

/* Copies `scale` (nedges factors, finite, >= 0, in the order of s->edge) into
 * edge_alpha_scale; NULL clears it. Returns 0, or -1 with err. Allocates. */
int pbd_set_edge_compliance_scale(pbd_t *s, const double *scale, verr_t *err);

/* Fixes node i (inverse mass 0) or sets its mass (kg, > 0). Change masses
 * only through these: the solver caches them per constraint. */
void pbd_fix_node(pbd_t *s, size_t i);
void pbd_set_node_mass(pbd_t *s, size_t i, double m);
/* Fixes every node whose rest z is below z; returns how many. */
size_t pbd_fix_below(pbd_t *s, double z);

static inline void pbd_add_force(pbd_t *s, uint32_t i, const double f[3]) {
  s->f_ext[3 * i] += f[0];
  s->f_ext[3 * i + 1] += f[1];
  s->f_ext[3 * i + 2] += f[2];
}

/* Advances by h in p.substeps sub-steps (pre may be NULL). If any coordinate
 * becomes non-finite, restores the state from before the call (a node that
 * was already non-finite goes back to rest, at rest) and returns -1. */
int pbd_step(pbd_t *s, double h, pbd_substep_fn pre, void *ctx);

/* Accuracy figures at the current positions. */
typedef struct pbd_errors {
  double strain_max, strain_rms; /* |L/L0 - 1| over distance constraints */
  double volume_global;          /* |sum V / sum V0 - 1| */
  double volume_worst;           /* max over tets of |V/V0 - 1| */
  double min_volume;             /* m^3, smallest signed tet volume */
  double min_volume_ratio;       /* smallest V/V0 */
  size_t inverted;               /* tets with V <= 0 */
} pbd_errors_t;
void pbd_errors(const pbd_t *s, pbd_errors_t *e);
/* |sum V / sum V0 - 1|: the published "volume_error". */
double pbd_volume_error(const pbd_t *s);

/* Kinetic + gravity + compliant constraint energy (XPBD: C^2 / 2 alpha,
 * home springs); rigid constraints (alpha 0) and PBD mode contribute
 * nothing for the constraints. J. */
double pbd_energy(const pbd_t *s);

/* Constraint force (N) acting on a set of nodes after the last step: the sum
 * over constraints of grad_i C lambda / h_sub^2 for i in nodes, distance,
 * volume and home constraints, into f (may be NULL); returns |f|. In XPBD
 * mode this is the elastic force of the last sub-step (for haptics); in PBD
 * mode it depends on the iteration count. Zero after a rollback. */
double pbd_constraint_force(pbd_t *s, const uint32_t *nodes, size_t count, double f[3]);

/* Constraint values and gradients, shared by the solver and the tests. */
static inline double pbd_distance_constraint(const double *xi, const double *xj, double rest, const double *ri,
                                             const double *rj, double n[3]) {
  double d0 = xi[0] - xj[0], d1 = xi[1] - xj[1], d2 = xi[2] - xj[2];
  double len = sqrt(d0 * d0 + d1 * d1 + d2 * d2);
  /* A zero-length edge has no direction; the rest direction (ri - rj, the
   * rest positions) separates the two nodes the way they sat at rest: a
   * mesh collapsed to a point unfolds instead of staying stuck. */
  if (!(len > 1e-300)) {
    d0 = ri[0] - rj[0];
    d1 = ri[1] - rj[1];
    d2 = ri[2] - rj[2];
    len = sqrt(d0 * d0 + d1 * d1 + d2 * d2);
    double il = len > 1e-300 ? 1.0 / len : 0;
    n[0] = d0 * il;
    n[1] = d1 * il;
    n[2] = d2 * il;
    return -rest;
  }
  double il = 1.0 / len;
  n[0] = d0 * il;
  n[1] = d1 * il;
  n[2] = d2 * il;
  return len - rest;
}

/* C = 6 (V - V0) and its four gradients g[0..3]. */
static inline double pbd_volume_constraint(const double *x0, const double *x1, const double *x2, const double *x3,
                                           double rest, double g[4][3]) {
  double a[3] = {x1[0] - x0[0], x1[1] - x0[1], x1[2] - x0[2]};
  double b[3] = {x2[0] - x0[0], x2[1] - x0[1], x2[2] - x0[2]};
  double c[3] = {x3[0] - x0[0], x3[1] - x0[1], x3[2] - x0[2]};
  g[1][0] = b[1] * c[2] - b[2] * c[1];
  g[1][1] = b[2] * c[0] - b[0] * c[2];
  g[1][2] = b[0] * c[1] - b[1] * c[0];
  g[2][0] = c[1] * a[2] - c[2] * a[1];
  g[2][1] = c[2] * a[0] - c[0] * a[2];
  g[2][2] = c[0] * a[1] - c[1] * a[0];
  g[3][0] = a[1] * b[2] - a[2] * b[1];
  g[3][1] = a[2] * b[0] - a[0] * b[2];
  g[3][2] = a[0] * b[1] - a[1] * b[0];
  for (int k = 0; k < 3; k++) g[0][k] = -(g[1][k] + g[2][k] + g[3][k]);
  return (g[3][0] * c[0] + g[3][1] * c[1] + g[3][2] * c[2]) - 6.0 * rest;
}

/* The scene models "pbd" and "xpbd" (model_pbd.c): a tetrahedral mesh built
 * from the surface (solver.tet_size) with the surface embedded in it. */
model_t *model_pbd_create(const model_params_t *p, verr_t *err);
/* The solver inside such a model (errors, constraint forces), or NULL when
 * m is another model. */
pbd_t *model_pbd_solver(model_t *m);

/* Topology edits of such a model (model.h edit, MODEL_EDIT_TETS: a cutter
 * such as cutting/tet_model_cut.h). A commit rebuilds the solver (new
 * nodes, distance constraints with rest lengths measured on the committed
 * rest configuration, volume constraints with rest volumes from it,
 * colouring, masses equal again with the total kept, the committed fixed
 * nodes, positions and velocities carried) and the surface, then
 * increments topology_version. From the first commit on, the render
 * surface is the committed boundary (incision faces included) instead of
 * the embedded organ surface, with a per-vertex 2D attribute
 * (model_pbd_surface_attr). A failed commit (out of memory) leaves the
 * model as it was. The model allocates nothing for editing until a commit.
 * 2 nsurf texture coordinates of the current surface, NULL before the first commit. */
const double *model_pbd_surface_attr(const model_t *m);

#endif
