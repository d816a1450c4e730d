/* SPDX-License-Identifier: Apache-2.0 */
#include "collision/cylinder.h"

#include <math.h>

#include "vmath.h"

int cylinder_test_node(const cylinder_t *c, const double n[3], cylinder_hit_t *hit) {
  double axis[3], a0[3], a1[3], back[3];
  v3_sub(axis, c->p1, c->p0);
  v3_sub(a0, n, c->p0);
  v3_sub(a1, n, c->p1);
  v3_scale(back, axis, -1);
  /* Step 1, the two angle tests: cos(angle) has the sign of the dot product. */
  double s0 = v3_dot(axis, a0); /* angle p1 p0 N */
  double s1 = v3_dot(back, a1); /* angle p0 p1 N */
  if (s0 < 0 || s1 < 0) return 0;
  /* Step 2, the radius test against the foot of the perpendicular, which
   * step 1 guarantees lies on the segment. */
  double len2 = v3_dot(axis, axis);
  double t = len2 > 0 ? s0 / len2 : 0;
  if (t > 1) t = 1; /* rounding only */
  double p[3], np[3];
  v3_copy(p, c->p0);
  v3_axpy(p, axis, t);
  v3_sub(np, p, n);
  double d = v3_norm(np);
  if (!(d < c->radius)) return 0;
  hit->t = t;
  hit->dist = d;
  v3_copy(hit->dir, np);
  v3_normalize(hit->dir);
  return 1;
}

size_t cylinder_nodes_scan(const cylinder_t *c, const double *x, size_t n, cylinder_hit_t *out, size_t cap) {
  size_t count = 0;
  for (size_t i = 0; i < n; i++) {
    cylinder_hit_t h;
    if (!cylinder_test_node(c, x + 3 * i, &h)) continue;
    h.node = (uint32_t)i;
    if (count < cap) out[count] = h;
    count++;
  }
  return count;
}

typedef struct grid_ctx {
  const cylinder_t *c;
  cylinder_hit_t *out;
  size_t cap, count;
} grid_ctx_t;

static void visit(void *vctx, uint32_t id, const double p[3]) {
  grid_ctx_t *g = vctx;
  cylinder_hit_t h;
  if (!cylinder_test_node(g->c, p, &h)) return;
  h.node = id;
  if (g->count < g->cap) g->out[g->count] = h;
  g->count++;
}

size_t cylinder_nodes_grid(const cylinder_t *c, const node_grid_t *g, cylinder_hit_t *out, size_t cap) {
  /* Every point of the cylinder lies within r of its axis segment, so the
   * segment's box grown by r holds them all. */
  double lo[3], hi[3];
  for (int k = 0; k < 3; k++) {
    lo[k] = fmin(c->p0[k], c->p1[k]) - c->radius;
    hi[k] = fmax(c->p0[k], c->p1[k]) + c->radius;
  }
  grid_ctx_t ctx = {c, out, cap, 0};
  node_grid_visit_box(g, lo, hi, visit, &ctx);
  return ctx.count;
}
