/* SPDX-License-Identifier: Apache-2.0 */
#include "runtime/topology_follow.h"

#include <math.h>
#include <string.h>

#include "vmath.h"
#include "vtime.h"

/* The proxy keeps to its side of thin tissue with the same bound. */
#define TOPO_SAME_SIDE_COS 0.2

double topo_max_edge_bound(const model_t *m) {
  double max_edge = 0;
  for (size_t t = 0; t < m->nsurf_tris; t++)
    for (int k = 0; k < 3; k++) {
      const uint32_t *tri = m->surf_tris + 3 * t;
      max_edge = fmax(max_edge, v3_dist(m->surf_rest + 3 * tri[k], m->surf_rest + 3 * tri[(k + 1) % 3]));
    }
  return 3 * max_edge;
}

void topo_capture(const runtime_t *rt, size_t organ, topo_anchor_t anchors[SCENE_MAX_TOOLS]) {
  const organ_rt_t *o = &rt->organs[organ];
  const model_t *m = o->model;
  for (size_t t = 0; t < rt->ntools; t++) {
    const proxy_t *p = &rt->tools[t].proxy;
    topo_anchor_t *a = &anchors[t];
    a->in_contact = p->in_contact && p->surface == (int)organ;
    a->face = a->in_contact && m->ops->surface_anchor ? m->ops->surface_anchor(m, p->tri) : UINT32_MAX;
    v3_copy(a->normal, p->normal);
  }
}

static void rest_normal(const model_t *m, uint32_t t, double n[3]) {
  const uint32_t *tri = m->surf_tris + 3 * (size_t)t;
  const double *x = m->surf_rest;
  double e1[3], e2[3];
  v3_sub(e1, x + 3 * tri[1], x + 3 * tri[0]);
  v3_sub(e2, x + 3 * tri[2], x + 3 * tri[0]);
  v3_cross(n, e1, e2);
  v3_normalize(n);
}

/* Nearest point of the model's current surface to q on a triangle whose
 * rest normal agrees with `normal`; falls back to any triangle if none
 * does. A rare event (a topology change), so a scan is fine. */
static uint32_t nearest_same_side(const model_t *m, const double q[3], const double normal[3], double bary[3]) {
  uint32_t best[2] = {UINT32_MAX, UINT32_MAX};
  double best_d[2] = {INFINITY, INFINITY}, best_b[2][3] = {{0}};
  for (size_t t = 0; t < m->nsurf_tris; t++) {
    const uint32_t *tri = m->surf_tris + 3 * t;
    double cp[3], b[3], n[3];
    tri_closest_point(q, m->surf_x + 3 * tri[0], m->surf_x + 3 * tri[1], m->surf_x + 3 * tri[2], cp, b);
    double d = v3_dist(cp, q);
    rest_normal(m, (uint32_t)t, n);
    int side = v3_dot(n, normal) >= TOPO_SAME_SIDE_COS ? 0 : 1;
    if (d < best_d[side]) {
      best_d[side] = d;
      best[side] = (uint32_t)t;
      v3_copy(best_b[side], b);
    }
  }
  int s = best[0] != UINT32_MAX ? 0 : 1;
  v3_copy(bary, best_b[s]);
  return best[s];
}

static void reattach(runtime_t *rt, size_t organ, proxy_t *p, const topo_anchor_t *a) {
  model_t *m = rt->organs[organ].model;
  double bary[3];
  uint32_t tri = UINT32_MAX;
  /* p->pos is where the hook last put the proxy, on the old surface at the
   * last sub-step: the point to keep. */
  if (m->ops->surface_locate && a->face != UINT32_MAX) tri = m->ops->surface_locate(m, a->face, p->pos, bary);
  if (tri == UINT32_MAX || tri >= m->nsurf_tris) tri = nearest_same_side(m, p->pos, a->normal, bary);
  if (tri == UINT32_MAX) { /* no triangles left: the contact has nothing to hold on to */
    proxy_reset(p);
    return;
  }
  /* Keep the proxy where it is; the difference to its new surface point
   * settles over PROXY_SETTLE_TAU (zero for a refinement, whose surface is
   * the old one). */
  double keep[3];
  v3_copy(keep, p->pos);
  v3_set(p->settle, 0, 0, 0);
  p->tri = tri;
  v3_copy(p->bary, bary);
  proxy_follow_surface(p, rt->surfaces, rt->norgans);
  v3_sub(p->settle, keep, p->pos);
  v3_copy(p->pos, keep);
}

int topo_follow(runtime_t *rt, size_t organ, const topo_anchor_t anchors[SCENE_MAX_TOOLS], verr_t *err) {
  uint64_t t0 = vtime_mono_ns();
  organ_rt_t *o = &rt->organs[organ];
  const model_t *m = o->model;
  int rc = 0;
  /* Build first, swap after: a failed build leaves no half tree behind. */
  aabb_tree_t tree;
  verr_t e;
  aabb_tree_destroy(&o->tree);
  if (m->nsurf_tris && aabb_tree_build(&tree, m->surf_x, m->nsurf, m->surf_tris, m->nsurf_tris, &e) == 0) {
    o->tree = tree;
  } else {
    rc = verr_set(err,
                  "organ '%s': collision tree rebuild after topology version %u failed (%s); proxies scan "
                  "every triangle",
                  o->cfg->name, m->topology_version, m->nsurf_tris ? e.msg : "no triangles");
  }
  rt->surfaces[organ] = (proxy_surface_t){.x = m->surf_x,
                                          .tris = m->surf_tris,
                                          .ntris = m->nsurf_tris,
                                          .max_edge = topo_max_edge_bound(m),
                                          .x_rest = m->surf_rest,
                                          .tree = rc ? NULL : &o->tree};
  for (size_t t = 0; t < rt->ntools; t++)
    if (anchors[t].in_contact) reattach(rt, organ, &rt->tools[t].proxy, &anchors[t]);
  o->topology_version = m->topology_version;
  o->topology_changes++;
  o->last_follow_us = (double)(vtime_mono_ns() - t0) * 1e-3;
  return rc;
}
