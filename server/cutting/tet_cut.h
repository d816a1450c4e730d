/* SPDX-License-Identifier: Apache-2.0 */
/* tet_cut: progressive cutting of a tetrahedral mesh by a moving blade
 * (docs/methods.md C §5.2-§5.3).
 *
 * The blade is a segment (tip, handle) without thickness. Each call to
 * tet_cut_advance() gives its new position; the quad it swept since the
 * previous call (tip0, tip1, handle1, handle0, as two triangles) is
 * intersected with the edges of the tetrahedra it can reach. Every cut edge
 * gets ONE intersection point, keyed by the edge (its two node ids), so
 * every tetrahedron sharing the edge uses the same point: the per-edge
 * table is the seed's per-tetrahedron state table (a tetrahedron's state is
 * the set of its six edges that are cut), stored once per edge so neighbours
 * cannot disagree.
 *
 * When is a tetrahedron split (docs/methods.md C: "when the blade leaves it"):
 *   - general case: its cut edges separate its four nodes into two groups
 *     (3 edges: one node from three, G1; 4 edges: two from two, G2) and the
 *     blade segment at its new position no longer intersects it;
 *   - partial case (blade tip inside, first and last tetrahedra, or a
 *     neighbour that shares a cut edge only): any other non-empty set of cut
 *     edges (P1: one edge, P2: two, P3: three or more without a separation);
 *     split at tet_cut_end() only.
 * Face points of the seed are not generated: the cut surface inside one
 * tetrahedron is the piecewise-planar surface through its edge points, so
 * the seed's five general cases reduce to G1 and G2 here (the three with a
 * face point differ only below the element size).
 *
 * How (tet_split.c): recursive bisection. A tetrahedron with cut edges is
 * bisected at the point of the cut edge created FIRST (global creation
 * order), each half again with the cut edges it still contains, until no
 * leaf contains a cut edge. A face is then refined by exactly the sequence
 * of its own cut edges in creation order, whichever tetrahedron refines it
 * and whenever: two tetrahedra sharing a face split it identically, no
 * T-cracks, even when one side is split steps after the other. Volumes add
 * up exactly (a bisection at parameter t gives t V and (1 - t) V); every
 * leaf keeps at least one node of its parent, so in a general case every
 * leaf lies on one side of the cut.
 *
 * Opening the incision: the leaves of a general case on opposite sides
 * share "cut faces" (three new points each), remembered. After every batch
 * of splits each new point whose edge no longer exists anywhere (all
 * tetrahedra around the edge are split) is examined: the tetrahedra around
 * it, connected through shared faces that are not cut faces, form one or
 * more groups; every group but the first gets its own copy of the point
 * (same position, velocity, rest position, attribute). A partially cut
 * neighbour around the edge bridges the two sides, so the point stays
 * single there: the crack front, a closed thin slit, never a T-crack.
 *
 * Snap rules (degenerate intersections never make flat or NaN elements):
 *   - a node whose distance to the blade's plane is below 1e-9 of the edge
 *     length counts as on the positive side (symbolic perturbation), so a
 *     cut through a node or along a face is decided consistently;
 *   - the intersection parameter along an edge is clamped to
 *     [snap, 1 - snap] (default 0.25, the field `snap`): no new point lies
 *     closer than a quarter of an edge to a node, which bounds the leaves'
 *     shape relative to their parent (on the spleen at 7 mm, one cut leaves
 *     a minimum radius ratio of 0.004 with 0.15, 0.031 with 0.25, 0.066
 *     with 0.33). A cut through a node thus passes a quarter edge beside it,
 *     and the incision deviates from the blade by up to snap x edge length;
 *   - a blade that did not move (zero-area quad) cuts nothing;
 *   - an edge shorter at rest than `min_edge` (default: half the mean rest
 *     edge of the mesh at create) is never cut: a tetrahedron whose cut
 *     would need it stays partial and the incision does not open there.
 *     This is the resolution limit that bounds refinement: without it each
 *     cut through already cut tissue crosses several times more (smaller,
 *     flatter) elements than the last, and 30 random incisions on the spleen
 *     grew it from 2,305 to 283,000 tetrahedra with radius ratios below
 *     1e-4. With it, an edge is bisected at most about three times;
 *   - likewise an edge of a tetrahedron whose rest radius ratio is below
 *     `min_quality` (default 0.1, or half the worst element's at create if
 *     that is lower) is never cut: poor elements are not split
 *     again, which bounds the quality loss over many cuts (each split of a
 *     tetrahedron of quality q leaves leaves of about q / 10 at worst).
 *
 * New nodes: rest position, position, velocity and attribute interpolated
 * linearly along the edge with the cut parameter (the seed's edge rule for
 * rest lengths, d_AP = d l_AP / (l_AP + l_PB), gives exactly |AP| at rest
 * then; see tet_cut_rest_edge / tet_cut_rest_face). A new node is fixed if
 * both ends of its edge are.
 *
 * The mesh grows by capacity doubling on topology changes only; advancing
 * the blade through tetrahedra already split allocates nothing. Every
 * change increments `version`. Not thread-safe. */
#ifndef VISCERA_TET_CUT_H
#define VISCERA_TET_CUT_H

#include <stddef.h>
#include <stdint.h>

#include "verr.h"

typedef struct tet_cut_stats {
  size_t cut_edges;               /* intersection points created (all sessions) */
  size_t split_general[2];        /* G1 (1|3), G2 (2|2) */
  size_t split_partial[3];        /* P1, P2, P3 */
  size_t duplicated;              /* node copies made to open the incision */
  double intersect_s, topology_s; /* wall time in intersection, in splitting + duplication */
} tet_cut_stats_t;

typedef struct tet_cut {
  /* The mesh, owned and growable (capacity doubling). */
  size_t n, ntets, cap_n, cap_t;
  double *x, *x_rest, *v; /* 3 cap_n */
  double *attr;           /* 2 cap_n, per-node 2D attribute (texture coordinates), interpolated */
  uint8_t *fixed;         /* cap_n */
  uint32_t *tet;          /* 4 cap_t, positive orientation at rest */
  uint8_t *tflag;         /* cap_t, internal */
  double snap;
  double min_edge;    /* m, rest length below which an edge is never cut (see the header) */
  double min_quality; /* an edge of a tetrahedron of lower rest radius ratio is never cut */
  uint32_t version;
  tet_cut_stats_t stats;
  struct tet_cut_priv *priv; /* edge table, state table, adjacency, session */
} tet_cut_t;

/* Copies the mesh (x_rest, positions x, velocities v may be NULL = at rest,
 * fixed may be NULL = none) and gives every node the attribute of a planar
 * projection of its rest position on the two largest extents of the mesh,
 * scaled to [0, 1]. Returns 0, or -1 with err. */
int tet_cut_create(tet_cut_t *c, size_t n, const double *x_rest, const double *x, const double *v, const uint8_t *fixed,
                   size_t ntets, const uint32_t *tets, verr_t *err);
void tet_cut_destroy(tet_cut_t *c);

/* The blade at its new position. The first call after create or end starts
 * a cut and only records the blade. Returns the number of tetrahedra split
 * in this call (>= 0), or -1 with err (non-finite blade, out of memory; the
 * mesh is then unchanged or consistent, never half-split). */
int tet_cut_advance(tet_cut_t *c, const double tip[3], const double handle[3], verr_t *err);
/* Ends the cut: splits every tetrahedron left with cut edges (partial
 * cases), opens the incision where it goes through. Returns the number of
 * tetrahedra split, or -1 with err. */
int tet_cut_end(tet_cut_t *c, verr_t *err);
int tet_cut_active(const tet_cut_t *c);

/* Checkpoints (a cut pbd/xpbd model's topology, cutting/tet_model_cut.h):
 * tet_cut_save appends the mesh (rest positions, attributes, fixed flags,
 * tetrahedra) and the cutter's memory of earlier cuts (cut edges with their
 * points and creation order, cut faces, the snap and quality gates, the
 * version) to b; node positions and velocities are not saved (the model
 * keeps them in its solver). tet_cut_load builds *c from such bytes
 * (untrusted: counts bounded by the bytes present, indices and values
 * checked); positions are the rest positions, velocities 0. A cut in
 * progress when saved is not restored: the restored cutter has none active,
 * and the tetrahedra that cut had crossed without splitting stay whole.
 * Returns 0, or -1 with err (*c then empty). */
struct state_blob;
void tet_cut_save(const tet_cut_t *c, struct state_blob *b);
int tet_cut_load(tet_cut_t *c, struct state_blob *b, verr_t *err);

/* Boundary faces (shared by one tetrahedron), outward, 3 per face, into a
 * malloc'ed array (*tris, freed by the caller); returns the count, or
 * (size_t)-1 on OOM. Includes the incision faces. */
size_t tet_cut_boundary(const tet_cut_t *c, uint32_t **tris);

/* The seed's rest-length rules (003 eq. 19-24), kept for comparison with
 * measuring the interpolated rest configuration (what the cutter uses):
 * edge point P on AB of rest length d, current lengths l_ap, l_pb;
 * face point P with barycentric (l1, l2, l3) in triangle ABC of rest edge
 * lengths d1 = |AB|, d2 = |BC|, d3 = |AC|: rest |AP|. */
double tet_cut_rest_edge(double d, double l_ap, double l_pb);
double tet_cut_rest_face(double d1, double d2, double d3, double l1, double l2, double l3);

/* Radius-ratio quality (3 r_in / r_circ, 1 regular, 0 flat; negative when
 * inverted) of tetrahedron i at positions x (3 n). */
double tet_cut_quality(const tet_cut_t *c, const double *x, size_t i);

#endif
