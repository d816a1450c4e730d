/* SPDX-License-Identifier: Apache-2.0 */
/* ms_cut: three-stage cutting of a surface mass-spring model with residual
 * stress (docs/methods.md D, Zhang et al. 2021, §2.1 and §2.3).
 *
 * The scalpel is a cylinder: axis segment p0 (handle side) -> p1 (tip) and
 * radius r. Each physics step the runtime calls ms_cut_step() with the blade
 * pose; the point where the axis first crosses the tissue surface (seen from
 * p0) is the tool's contact point, and the sequence of contact points is the
 * cut path. While the axis crosses the surface the cut goes on; when it stops
 * crossing, or at ms_cut_end() (the button released), the cut ends.
 *
 * The path is processed in segments (every `segment_length` of path, and at
 * the end), each through the seed's three stages:
 *   1. swept-volume deletion (ms_cut_sweep.c): the tool's circular region of
 *      radius r_eff = max(r, min_radius_rel x mean edge) swept along the
 *      segment's path is the capsule set {p : dist(p, path) < r_eff}. Nodes
 *      inside it and springs passing through it (segment-to-path distance
 *      < r_eff) are deleted with their triangles; triangles left hanging by
 *      one vertex or with two edges on the hole go too, so the hole boundary
 *      is a set of simple chains. r_eff has a floor because a blade thinner
 *      than a third of an edge would leave sliver triangles along the curve.
 *   2. the incision curve (bezier.h): a cubic Bezier through the segment's
 *      path (eq. 5-8), in current and in rest positions.
 *   3. shortest-distance node matching (node_match.h): every node on the
 *      hole boundary is connected to its nearest point of the curve, the
 *      quadrilaterals between neighbours are split by their shorter diagonal
 *      (Algorithm 2, Fig. 3). Each side of the incision gets its own curve
 *      nodes (the lips), so the wound can open; the curve's end points are
 *      shared by both sides where the incision ends inside the tissue and
 *      duplicated where it reaches a boundary (the tissue's edge or the
 *      previous segment's wound), so a cut all the way across separates.
 * Then the model's nodes (survivors compacted, curve nodes appended with the
 * per-node mass of the uncut model), triangles and springs are replaced, the
 * sub-steps re-chosen from a bound valid at once and topology_version
 * incremented; the following ms_cut_step calls refine that bound by a few
 * power iterations each (model.h edit->refine), so call it every step, with
 * the blade away from the tissue too.
 *
 * Residual stress (eq. 3-4). sigma_r = E eps_r acts where springs were cut.
 * A spring of stiffness K and rest length L0 stands for a bundle of tissue
 * of cross-section A with E A / L0 = K (a bar's axial stiffness), so the
 * residual stress carried through it is the force sigma_r A = E eps_r K L0 / E
 * = eps_r K L0: the tension of the spring at strain eps_r; E cancels and
 * needs no scene value. Before the cut the tissue's pre-tension is in
 * equilibrium; cutting spring (i, j) removes the pull of j on i, so the
 * surviving node i gets the constant force eps_r K L0 u, u the unit rest
 * direction from j to i (away from the cut), for good (mass_spring f_res:
 * eq. 4 adds sigma_r to F_i). The wound gapes fast, overshoots (inertia)
 * and shrinks back to the width where the springs and home springs balance
 * the released tension: the seed's Fig. 6.
 *
 * Allocation: ms_cut_create() (called when the scene has a cutting tool)
 * allocates this object and has the model keep the dominant vectors of its
 * stability bound (2 x 3 doubles per node, one power iteration at load) for
 * quick re-estimates after each segment; the node-triangle adjacency and
 * path arrays are allocated when the blade first comes near the tissue, the
 * residual force array at the first cut; a topology change grows
 * capacities (never per step). A model nobody cuts allocates none of this.
 * ms_cut_bytes() reports what is held.
 * Works on mass_spring_surface only (mass_spring_tet is refused: its render
 * surface is embedded in tetrahedra, which this method does not cut).
 * Not thread-safe: called from the physics thread between steps. */
#ifndef VISCERA_MS_CUT_H
#define VISCERA_MS_CUT_H

#include <stddef.h>
#include <stdint.h>

#include "physics/model.h"
#include "verr.h"

typedef struct ms_cut_params {
  double eps_r;          /* residual strain (docs/methods.md D: 0.1); 0 disables residual stress */
  double segment_length; /* m of path per processed segment; 0: 4 x the mean rest edge length */
  double min_radius_rel; /* floor of the swept radius, x mean rest edge length (default 0.3) */
  double max_radius;     /* m, larger blade radii are refused (default 0.02) */
} ms_cut_params_t;

ms_cut_params_t ms_cut_default_params(void);

typedef struct ms_cut_stats {
  uint64_t steps_in_contact; /* steps where the blade axis crossed the surface */
  uint64_t cuts;             /* cuts started */
  uint64_t segments;         /* segments processed (topology changes) */
  uint64_t nodes_deleted, nodes_added, tris_deleted, tris_added, springs_cut;
  uint64_t holes_left_open; /* hole boundaries the curve could not close (e.g. a stab without travel) */
  double last_segment_ms;   /* wall time of the last segment's three stages + rebuild, ms */
} ms_cut_stats_t;

typedef struct ms_cut ms_cut_t;

/* Refuses (NULL, err) a model without surface topology edits (model.h edit
 * kind MODEL_EDIT_SURFACE: mass_spring_surface) and bad params. The caller
 * owns the cutter and destroys it before the model. The cutter acts on the
 * model only through model.h's edit operations. */
ms_cut_t *ms_cut_create(model_t *m, const ms_cut_params_t *p, verr_t *err);
void ms_cut_destroy(ms_cut_t *c);

/* One call per physics step (before or after model step, not inside it):
 * blade axis p0 (handle) -> p1 (tip), radius (m). Returns 1 when the surface
 * topology changed (m->topology_version was incremented), 0 when not, -1 with
 * err on invalid input (non-finite, radius <= 0 or > max_radius) or when a
 * segment could not be applied (model unchanged in both cases), and also
 * when the cut mesh was applied but would need more sub-steps than allowed
 * or memory ran out while its springs were rebuilt: then topology_version
 * did change (the runtime compares it after every step anyway) and err says
 * what failed. */
int ms_cut_step(ms_cut_t *c, const double p0[3], const double p1[3], double radius, verr_t *err);
/* Ends the current cut (processes the rest of the path). Returns as ms_cut_step. */
int ms_cut_end(ms_cut_t *c, verr_t *err);

int ms_cut_active(const ms_cut_t *c);
const ms_cut_stats_t *ms_cut_stats(const ms_cut_t *c);
/* Bytes of cutting structures held (this object excluded): the model's
 * dominant vectors from create on, more once the blade comes near. */
size_t ms_cut_bytes(const ms_cut_t *c);

/* Incision width (docs/methods.md D §4.1: distance between points on both sides):
 * for every lip node of side 1 (curve ends shared with side 2 excluded) its distance to
 * the nearest lip polyline of side 2 at the current positions; mean and max
 * over them, m. Returns the number of nodes measured (0: no incision yet). */
size_t ms_cut_incision_width(const ms_cut_t *c, double *mean, double *max);

/* The lips of every processed segment: node indices (current numbering) of
 * side s (1 or 2), as polylines along the curve. For tests and the viewer. */
size_t ms_cut_lip_count(const ms_cut_t *c);
const uint32_t *ms_cut_lip(const ms_cut_t *c, size_t k, int side, size_t *len);

#endif
