/* SPDX-License-Identifier: Apache-2.0 */
#include "runtime/vertex_cull.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A segment's boxes: pieces about this many radii long (a long tilted
 * shaft's one box would hold a slab of the organ), at most
 * VERTEX_CULL_PIECES of them. */
#define VERTEX_CULL_PIECE_RADII 8.0
#define VERTEX_CULL_PIECES 64

void vertex_cull_free(vertex_cull_t *c) {
  free(c->bits);
  free(c->out);
  memset(c, 0, sizeof *c);
}

int vertex_cull_setup(vertex_cull_t *c, size_t nverts, const uint32_t *tris, size_t ntris, verr_t *err) {
  vertex_cull_free(c);
  size_t nw = (nverts + 63) / 64;
  c->bits = calloc(nw ? nw : 1, sizeof *c->bits);
  c->out = malloc((nverts ? nverts : 1) * sizeof *c->out);
  if (!c->bits || !c->out) {
    vertex_cull_free(c);
    return verr_set(err, "vertex_cull: out of memory for %zu vertices", nverts);
  }
  c->nverts = nverts;
  c->ntris = ntris;
  /* Every vertex a corner? (bits as scratch, cleared after.) */
  for (size_t t = 0; t < 3 * ntris; t++)
    if (tris[t] < nverts) c->bits[tris[t] / 64] |= (uint64_t)1 << (tris[t] % 64);
  size_t used = 0;
  for (size_t w = 0; w < nw; w++) used += (size_t)__builtin_popcountll(c->bits[w]);
  c->complete = used == nverts;
  memset(c->bits, 0, nw * sizeof *c->bits);
  return 0;
}

int vertex_cull_usable(const vertex_cull_t *c, const aabb_tree_t *tree, const double *x, size_t nverts, size_t ntris) {
  return c->bits && c->complete && tree && tree->ntris && c->nverts == nverts && c->ntris == ntris &&
         tree->nverts == nverts && tree->ntris == ntris && tree->x == x;
}

void vertex_cull_begin(vertex_cull_t *c) {
  c->wlo = SIZE_MAX;
  c->whi = 0;
  c->overflow = !c->bits;
}

void vertex_cull_add(vertex_cull_t *c, uint32_t i) {
  if (i >= c->nverts) return;
  size_t w = i / 64;
  c->bits[w] |= (uint64_t)1 << (i % 64);
  if (w < c->wlo) c->wlo = w;
  if (w + 1 > c->whi) c->whi = w + 1;
}

static void add_corner(void *ctx, uint32_t i) { vertex_cull_add(ctx, i); }

void vertex_cull_box(vertex_cull_t *c, const aabb_tree_t *tree, const double lo[3], const double hi[3]) {
  if (!c->overflow) aabb_tree_box_corners(tree, lo, hi, add_corner, c);
}

size_t vertex_cull_take(vertex_cull_t *c, const uint32_t **out) {
  size_t n = 0;
  for (size_t w = c->wlo; w < c->whi; w++) {
    for (uint64_t b = c->bits[w]; b; b &= b - 1) c->out[n++] = (uint32_t)(64 * w + (size_t)__builtin_ctzll(b));
    c->bits[w] = 0;
  }
  c->wlo = SIZE_MAX;
  c->whi = 0;
  *out = c->out;
  return c->overflow ? SIZE_MAX : n;
}

size_t vertex_cull_segment(vertex_cull_t *c, const aabb_tree_t *tree, const double p0[3], const double p1[3],
                           double radius, const uint32_t *moved, size_t nmoved, const uint32_t **out) {
  vertex_cull_begin(c);
  double d[3], len = 0;
  for (int k = 0; k < 3; k++) {
    d[k] = p1[k] - p0[k];
    len += d[k] * d[k];
  }
  len = sqrt(len);
  double want = len / (VERTEX_CULL_PIECE_RADII * radius);
  size_t np = want >= VERTEX_CULL_PIECES ? VERTEX_CULL_PIECES : want >= 1 ? (size_t)ceil(want) : 1;
  if (!(len == len) || !(radius >= 0)) c->overflow = 1; /* NaN shaft: let the scan decide */
  /* A point within radius of the segment is within radius of a point of
   * one piece, so in that piece's box grown by radius; the pad covers the
   * rounding of the pieces' ends and of the node test's own distance. */
  for (size_t i = 0; i < np && !c->overflow; i++) {
    double ta = (double)i / (double)np, tb = (double)(i + 1) / (double)np, lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
      double a = p0[k] + ta * d[k], b = i + 1 == np ? p1[k] : p0[k] + tb * d[k];
      double g = radius * (1 + VERTEX_CULL_PAD) + VERTEX_CULL_PAD * (1e-3 * (fabs(a) + fabs(b)) + len);
      lo[k] = fmin(a, b) - g;
      hi[k] = fmax(a, b) + g;
    }
    vertex_cull_box(c, tree, lo, hi);
  }
  for (size_t j = 0; j < nmoved && !c->overflow; j++) vertex_cull_add(c, moved[j]);
  return vertex_cull_take(c, out);
}
