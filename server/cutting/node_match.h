/* SPDX-License-Identifier: Apache-2.0 */
/* node_match: stage 3 of docs/methods.md D's cutting (§2.3.3, Algorithm 2, Fig. 3),
 * the shortest-distance nodes matching method, on the hole that stage 1 left.
 *
 * Input: the hole's boundary as directed edges u -> v with the hole on
 * their left (the deleted triangles' own edges whose twins survive), the
 * node positions, and the incision curve (cubic Bezier, bezier.h).
 *
 * 1. The edges are linked into chains: open chains run from one existing
 *    boundary (the tissue's edge, an earlier wound) to another; closed loops
 *    surround a hole inside the tissue.
 * 2. Each chain node finds its nearest point of the curve (parameter a): the
 *    seed's red springs. Nodes whose nearest point is an end of the curve
 *    (within merge_tol of it) connect to that end: the seed's yellow nodes.
 *    A loop is split into the two sides of the incision at the nodes nearest
 *    the two curve ends; an open chain that starts and ends near the same
 *    end of the curve is split at its node nearest the other end. An end
 *    where two sides meet is one shared curve node at the curve's end (the
 *    incision closes there); a chain end on an existing boundary gets its
 *    own node where that chain end projects on the curve (the incision is
 *    open there, and a chain bordering only part of the curve, e.g. beyond
 *    an earlier wound it crosses, gets a lip over that part only).
 * 3. Every side gets its own curve nodes (its lip): one per group of chain
 *    nodes whose nearest points lie within merge_tol (arc length) of each
 *    other, at the group's mean parameter, so the two lips can separate.
 * 4. The strip between a side's chain and its lip is triangulated: between
 *    neighbours b_i, b_i+1 connected to lip nodes c_j, c_j+1 lies the
 *    quadrilateral (b_i, b_i+1, c_j+1, c_j), split by its shorter diagonal
 *    (the seed's green springs); neighbours connected to the same lip node
 *    give one triangle; lip nodes no chain node chose are fanned in between.
 *    Triangles follow the chain's orientation, so they are consistently
 *    oriented with the mesh.
 * 5. Slivers the strip still makes (a chain running along the curve, fans
 *    at the curve's ends) are flipped away: an edge between two new
 *    triangles, one with an angle below 15 degrees, becomes the other
 *    diagonal of their quadrilateral when that raises the smaller angle
 *    (regular quadrilaterals keep the seed's shorter diagonal).
 * Loops whose ends coincide (a path shorter than merge_tol) are left open
 * and counted. Allocates the result; no global state. */
#ifndef VISCERA_NODE_MATCH_H
#define VISCERA_NODE_MATCH_H

#include <stddef.h>
#include <stdint.h>

#include "verr.h"

typedef struct nm_lip {
  int side; /* 1: right of the curve's direction (P0 -> P3), seen from the surface's outside; 2: left */
  size_t len;
  uint32_t *nodes; /* indices >= n: new nodes (n + k); ordered along the curve from a = 0 to 1 */
} nm_lip_t;

typedef struct nm_result {
  size_t nnew;
  double *a; /* nnew: curve parameter of new node n + k */
  size_t ntris;
  uint32_t *tris; /* 3 ntris, indices < n + nnew */
  size_t nmatch;
  uint32_t *match_node, *match_to; /* the connection made for every chain node (red/yellow springs) */
  size_t nlips;
  nm_lip_t *lips;   /* one per side chain, with its curve end nodes */
  size_t open_left; /* boundary components left open */
} nm_result_t;

/* n nodes at x; nedges directed hole edges (2 indices each); ctrl the curve
 * in current positions; merge_tol (m) the arc-length tolerance above.
 * Returns 0 or -1 with err (OOM, index out of range). */
int node_match(size_t n, const double *x, size_t nedges, const uint32_t *edges, const double ctrl[4][3],
               double merge_tol, nm_result_t *out, verr_t *err);
void nm_result_free(nm_result_t *r);

#endif
