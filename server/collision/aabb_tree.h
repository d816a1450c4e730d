/* SPDX-License-Identifier: Apache-2.0 */
/* aabb_tree: a bounding-volume hierarchy of axis-aligned boxes over a
 * deforming triangle surface (docs/methods.md A §3.1).
 *
 * Built once: each node's triangles are split at the median of their
 * centroids along the longest axis of the node's box (moved by at most three
 * triangles so that leaves come out full), so the tree is balanced (depth
 * about log2(n / 4)) whatever the shape. The seed splits at the middle of the
 * axis instead; the median never leaves a side empty and bounds the depth,
 * which lets every query run on a fixed stack. Leaves hold 1-4 triangles,
 * mostly 4: the seed's one-triangle leaves would mean four times the nodes
 * for a query to fetch (leaves of 2 and of 4 measured the same on the liver).
 *
 * The topology never changes after the build: while the organ deforms only
 * the boxes are recomputed (aabb_tree_refit). Leaf boxes are fattened by a
 * margin around the vertex positions they were last computed from; refit
 * checks every vertex against its own last position and recomputes only
 * the leaves of vertices that moved beyond the margin, and the internal
 * nodes on their paths to the root. A resting organ's refit then touches
 * no box at all, a probed one only the dent's paths (docs/methods.md A
 * §3.1). The boxes still contain every triangle, so queries stay exact;
 * strongly deformed meshes let boxes overlap more, so queries slow down
 * gracefully rather than fail; rebuild (destroy + build) after a topology
 * change such as a cut.
 *
 * Queries read positions from the array given to the last build or refit and
 * boxes from that refit: refit after every change of positions (each physics
 * step). Results are exact, identical to a brute-force scan over all
 * triangles (same per-triangle tests; ties go to the lowest triangle index),
 * also when a blown-up simulation feeds NaN or infinite positions to refit.
 * Build and destroy allocate; refit and queries never do. A tree may be
 * queried from several threads at once, but not while it is being refit. */
#ifndef VISCERA_AABB_TREE_H
#define VISCERA_AABB_TREE_H

#include <stddef.h>
#include <stdint.h>

#include "verr.h"

#define AABB_TREE_LEAF_MAX 4
/* The median split halves every node (give or take three triangles), so the
 * depth stays near log2(ntris / 4) + 1, under 30 for the 2^28 triangles a
 * leaf reference can address; queries keep their pending subtrees on a
 * stack this deep, and build refuses a deeper tree. */
#define AABB_TREE_STACK 64
/* A child reference is an internal node's index or, with AABB_LEAF set, a
 * leaf: its first slot in the leaf order (bits 0-27) and its triangle count
 * (bits 28-30). Leaves are not nodes of their own: their boxes sit in the
 * parent, so a leaf costs no extra memory fetch. */
#define AABB_LEAF 0x80000000u
#define AABB_LEAF_FIRST(ref) ((ref)&0x0fffffffu)
#define AABB_LEAF_COUNT(ref) (((ref) >> 28) & 7u)

typedef struct aabb_node {
  /* The boxes of both children, [axis][child], as floats rounded outward
   * (each float box contains the exact one): a visit reads both children's
   * boxes from this one 64-byte line, and float halves the tree's memory. */
  float lo[3][2], hi[3][2];
  uint32_t child[2];
  uint32_t parent; /* the node holding this one's box, UINT32_MAX for the root */
  uint32_t unused;
} aabb_node_t;

typedef struct aabb_tree {
  aabb_node_t *nodes;  /* internal nodes in pre-order (children after parents), 64-byte aligned */
  size_t nnodes;       /* 0 when every triangle fits in one leaf */
  uint32_t root;       /* node 0, or the only leaf */
  double lo[3], hi[3]; /* the root's box */
  size_t ntris, nverts;
  uint32_t *tri_id; /* ntris: original triangle index of each leaf slot */
  uint32_t *tri_v;  /* 3 * ntris: the slot's vertex indices, copied so a leaf reads one run of memory */
  /* Refit's view of the leaves: each leaf's distinct vertices (a vertex is
   * shared by ~6 triangles, so this reads half as many as the triangle
   * corners would) and where its box goes: parent node << 1 | child, or
   * UINT32_MAX when the only leaf is the root. */
  size_t nleaves;
  uint32_t *leaf_parent; /* nleaves */
  uint32_t *leaf_voff;   /* nleaves + 1: ranges of leaf_vidx */
  uint32_t *leaf_vidx;
  const double *x; /* 3 per vertex: positions of the last build or refit (not owned) */
  double pad;      /* m added around every leaf box, see aabb_tree_build */
  int depth;       /* levels of boxes, root = 1, leaves included */
  /* Refit over what moved: each leaf box holds every one of its vertices'
   * xr +- margin (max norm), so a vertex whose position is still within
   * margin of its xr needs no box changed. vleaf_off/vleaf: the leaves of
   * each vertex (CSR, nverts + 1 offsets). */
  double margin; /* m, see aabb_tree_set_margin */
  double *xr;    /* 3 per vertex: the position each vertex's leaf boxes were computed from */
  uint32_t *vleaf_off, *vleaf;
  uint32_t *dirty;                      /* nleaves: scratch list of the leaves a refit recomputes */
  unsigned char *leaf_mark, *node_mark; /* nleaves, nnodes: scratch flags, zero between refits */
  uint32_t *vmoved;                     /* nverts: scratch, the vertices a refit found moved */
  int full;                             /* the next refit recomputes every box (after build or a margin change) */
  /* What the last refit did: leaf boxes and internal nodes recomputed. */
  size_t refit_leaves, refit_nodes;
} aabb_tree_t;

/* Builds the tree over triangles `tris` (3 per triangle, indices < nverts)
 * at positions x (3 per vertex), which must stay valid until the next refit
 * or destroy; `tris` is copied. Returns 0, or -1 with err (no triangles, bad
 * index, non-finite position, too many triangles, out of memory). */
int aabb_tree_build(aabb_tree_t *t, const double *x, size_t nverts, const uint32_t *tris, size_t ntris, verr_t *err);
void aabb_tree_destroy(aabb_tree_t *t);

/* Makes the boxes contain positions x (the same vertex count; may be the
 * build's array after it changed or another array): recomputes the leaf
 * boxes of vertices that moved more than the margin along some axis since
 * their boxes were computed (NaN and infinite coordinates count as moved),
 * and the nodes above them. O(vertices) compares plus O(moved leaves x
 * depth) boxes; when more than an eighth of the vertices moved, every box
 * (the plain bottom-up sweep, cheaper then). No allocation. */
void aabb_tree_refit(aabb_tree_t *t, const double *x);
/* The same refit, the same boxes, looking only at the n vertices in idx
 * (each once; indices past the vertex count are ignored): for a caller
 * that knows every other vertex is bit for bit where it was at the last
 * refit or the build, in the same array x (a model's last_step_moved).
 * O(n) compares instead of O(vertices); with another array than the last
 * refit's it falls back to aabb_tree_refit. */
void aabb_tree_refit_listed(aabb_tree_t *t, const double *x, const uint32_t *idx, size_t n);

/* The build's margin: this fraction of the mean triangle edge length at the
 * build. A vertex resting or creeping below it costs one compare per refit;
 * a larger margin lets boxes overlap more (a nearest query near the
 * surface visits a few more leaves). */
#define AABB_TREE_MARGIN_EDGE 0.1
/* Sets the margin (m, >= 0; 0 gives tight boxes recomputed on any motion);
 * the next refit recomputes every box. */
void aabb_tree_set_margin(aabb_tree_t *t, double margin);

typedef struct aabb_nearest {
  uint32_t tri;   /* original triangle index */
  double bary[3]; /* of the nearest point in that triangle (sum 1) */
  double point[3];
  double dist2; /* squared distance from the query point */
  /* Seed 003 §4.1's penetration test on the nearest triangle: the query point
   * makes an angle over 90 degrees with the outward normal seen from the
   * triangle's centroid, i.e. it lies behind the triangle's plane. */
  int behind;
} aabb_nearest_t;

/* Nearest point of the surface to q, by branch and bound: subtrees whose box
 * is farther than the best triangle so far are skipped, nearer child first.
 * Only triangles with squared distance strictly below max_dist2 count
 * (INFINITY: any). Returns 1 and fills *out, or 0 if none qualified. */
int aabb_tree_nearest(const aabb_tree_t *t, const double q[3], double max_dist2, aabb_nearest_t *out);

enum {
  AABB_SEG_ANY = 0,
  /* Only triangles the segment enters from outside: direction . outward
   * normal < 0 (the normal of the current, deformed triangle). */
  AABB_SEG_ENTERING = 1
};

typedef struct aabb_hit {
  uint32_t tri; /* original triangle index */
  double t;     /* segment parameter in [0, 1] */
  double bary[3];
  double point[3];
  /* Seed 000 §3.1 contact point: the triangle's vertex nearest the
   * intersection point (original vertex index). */
  uint32_t vertex;
} aabb_hit_t;

/* First triangle along p0 -> p1 (smallest t; ties to the lowest triangle
 * index), using seg_tri_intersect. Only hits with t strictly below t_max
 * count (INFINITY: the whole segment). flags: AABB_SEG_*. Returns 1 and
 * fills *out, or 0. */
int aabb_tree_segment_first(const aabb_tree_t *t, const double p0[3], const double p1[3], int flags, double t_max,
                            aabb_hit_t *out);

/* Every triangle that overlaps the box [lo, hi] (exact triangle-box test,
 * touching counts; a non-finite or inverted box selects nothing). Writes up to cap original triangle indices to out (in
 * tree order) and returns how many there are in all, which may exceed cap. */
size_t aabb_tree_box_query(const aabb_tree_t *t, const double lo[3], const double hi[3], uint32_t *out, size_t cap);

/* Every corner of a triangle in a leaf whose box overlaps [lo, hi] and
 * whose position (the array the tree reads, as it is now) lies in the
 * closed box: fn(ctx, vertex index), a vertex shared by several such
 * triangles once per triangle. A vertex that has not moved since the last
 * refit lies in its leaves' boxes, so every such vertex in the box is
 * reported (runtime/vertex_cull.h). A NaN bound reports nothing. */
typedef void (*aabb_corner_fn)(void *ctx, uint32_t vertex);
void aabb_tree_box_corners(const aabb_tree_t *t, const double lo[3], const double hi[3], aabb_corner_fn fn, void *ctx);

/* Exact triangle vs axis-aligned box overlap by separating axes (box
 * faces, triangle normal, the nine edge cross products); touching counts.
 * 0 for a non-finite or inverted box and for a triangle with a NaN corner.
 * Exposed for tests and brute-force references. */
int tri_box_overlap(const double a[3], const double b[3], const double c[3], const double lo[3], const double hi[3]);

#endif
