/* SPDX-License-Identifier: Apache-2.0 */
#include "haptics/proxy.h"

#include <math.h>
#include <string.h>

#include "collision/aabb_tree.h"
#include "vmath.h"

static void tri_vertices(const proxy_surface_t *s, uint32_t t, const double **a, const double **b, const double **c) {
  *a = s->x + 3 * s->tris[3 * t];
  *b = s->x + 3 * s->tris[3 * t + 1];
  *c = s->x + 3 * s->tris[3 * t + 2];
}

static void tri_normal(const proxy_surface_t *s, uint32_t t, double n[3]) {
  const double *a, *b, *c;
  double e1[3], e2[3];
  tri_vertices(s, t, &a, &b, &c);
  v3_sub(e1, b, a);
  v3_sub(e2, c, a);
  v3_cross(n, e1, e2);
  v3_normalize(n);
}

void proxy_reset(proxy_t *p) {
  memset(p, 0, sizeof *p);
  p->surface = -1;
}

void proxy_follow_surface(proxy_t *p, const proxy_surface_t *surfaces, size_t nsurfaces) {
  if (!p->in_contact || p->surface < 0 || (size_t)p->surface >= nsurfaces) return;
  const proxy_surface_t *s = &surfaces[p->surface];
  const double *a, *b, *c;
  tri_vertices(s, p->tri, &a, &b, &c);
  for (int k = 0; k < 3; k++) p->pos[k] = p->bary[0] * a[k] + p->bary[1] * b[k] + p->bary[2] * c[k] + p->settle[k];
  proxy_surface_t rest = *s;
  if (s->x_rest) rest.x = s->x_rest;
  tri_normal(&rest, p->tri, p->normal);
  const uint32_t *tri = s->tris + 3 * p->tri;
  if (s->vn && tri[0] < s->nvn && tri[1] < s->nvn && tri[2] < s->nvn) {
    /* Force shading: interpolated vertex normals; fall back to the face
     * normal where they cancel (a knife edge) or point away from it. */
    double n[3] = {0, 0, 0};
    for (int k = 0; k < 3; k++) v3_axpy(n, s->vn + 3 * tri[k], p->bary[k]);
    if (v3_normalize(n) > 1e-9 && v3_dot(n, p->normal) > 0.2) v3_copy(p->normal, n);
  }
}

void proxy_vertex_normals(size_t nverts, const double *x, size_t ntris, const uint32_t *tris, double *vn) {
  memset(vn, 0, 3 * nverts * sizeof *vn);
  for (size_t t = 0; t < ntris; t++) {
    const uint32_t *tri = tris + 3 * t;
    double e1[3], e2[3], n[3];
    v3_sub(e1, x + 3 * tri[1], x + 3 * tri[0]);
    v3_sub(e2, x + 3 * tri[2], x + 3 * tri[0]);
    v3_cross(n, e1, e2); /* length = twice the area: area weighting for free */
    for (int k = 0; k < 3; k++) v3_add(vn + 3 * tri[k], vn + 3 * tri[k], n);
  }
  for (size_t i = 0; i < nverts; i++) v3_normalize(vn + 3 * i);
}

/* The surface's tree, if it describes this surface: a tree refit from
 * another array (or built over another triangle list) would answer for a
 * different surface, so the scan runs instead. */
static const aabb_tree_t *usable_tree(const proxy_surface_t *s) {
  const aabb_tree_t *t = s->tree;
  return t && t->x == s->x && t->ntris == s->ntris ? t : NULL;
}

/* Nearest surface point to q over all triangles of all surfaces; ties go to
 * the first surface, then the lowest triangle. Every point
 * of a triangle lies within its longest edge of its first vertex, so a
 * triangle whose first vertex is farther than best + max_edge cannot win:
 * one dot product skips the exact test for almost every triangle. A tree
 * finds the same triangle by branch and bound, seeded with the best distance
 * of the surfaces before it so it only reports a strictly nearer one. */
static void nearest_on_surfaces(const double q[3], const proxy_surface_t *surfaces, size_t nsurfaces, proxy_t *p) {
  double best = INFINITY;
  for (size_t si = 0; si < nsurfaces; si++) {
    const proxy_surface_t *s = &surfaces[si];
    const aabb_tree_t *tree = usable_tree(s);
    if (tree) {
      aabb_nearest_t r;
      if (aabb_tree_nearest(tree, q, best, &r)) {
        best = r.dist2;
        p->surface = (int)si;
        p->tri = r.tri;
        v3_copy(p->bary, r.bary);
        v3_copy(p->pos, r.point);
      }
      continue;
    }
    for (size_t t = 0; t < s->ntris; t++) {
      const double *a, *b, *c;
      tri_vertices(s, (uint32_t)t, &a, &b, &c);
      double da[3];
      v3_sub(da, a, q);
      double reach = sqrt(best) + s->max_edge;
      if (s->max_edge > 0 && isfinite(best) && v3_dot(da, da) > reach * reach) continue;
      double cp[3], bary[3], d[3];
      tri_closest_point(q, a, b, c, cp, bary);
      v3_sub(d, cp, q);
      double d2 = v3_dot(d, d);
      if (d2 < best) {
        best = d2;
        p->surface = (int)si;
        p->tri = (uint32_t)t;
        v3_copy(p->bary, bary);
        v3_copy(p->pos, cp);
      }
    }
  }
}

/* First triangle the device path enters from outside (smallest segment
 * parameter; ties to the first surface, then the lowest triangle). */
static int find_entry(const double p0[3], const double p1[3], const proxy_surface_t *surfaces, size_t nsurfaces,
                      proxy_t *p) {
  double best_t = INFINITY, dir[3], seg_lo[3], seg_hi[3];
  v3_sub(dir, p1, p0);
  for (int k = 0; k < 3; k++) {
    seg_lo[k] = fmin(p0[k], p1[k]);
    seg_hi[k] = fmax(p0[k], p1[k]);
  }
  for (size_t si = 0; si < nsurfaces; si++) {
    const proxy_surface_t *s = &surfaces[si];
    const aabb_tree_t *tree = usable_tree(s);
    if (tree) {
      aabb_hit_t h;
      if (aabb_tree_segment_first(tree, p0, p1, AABB_SEG_ENTERING, best_t, &h)) {
        best_t = h.t;
        p->surface = (int)si;
        p->tri = h.tri;
        v3_copy(p->bary, h.bary);
      }
      continue;
    }
    for (size_t t = 0; t < s->ntris; t++) {
      const double *a, *b, *c;
      double tt, bary[3], n[3];
      tri_vertices(s, (uint32_t)t, &a, &b, &c);
      /* Box test first: the segment's bounds against the triangle's. */
      int apart = 0;
      for (int k = 0; k < 3 && !apart; k++) {
        double lo = fmin(a[k], fmin(b[k], c[k])), hi = fmax(a[k], fmax(b[k], c[k]));
        apart = hi < seg_lo[k] || lo > seg_hi[k];
      }
      if (apart) continue;
      if (!seg_tri_intersect(p0, p1, a, b, c, &tt, bary) || tt >= best_t) continue;
      tri_normal(s, (uint32_t)t, n);
      if (v3_dot(dir, n) >= 0) continue; /* leaving, not entering */
      best_t = tt;
      p->surface = (int)si;
      p->tri = (uint32_t)t;
      v3_copy(p->bary, bary);
    }
  }
  return isfinite(best_t);
}

int proxy_update(proxy_t *p, const double device[3], const proxy_surface_t *surfaces, size_t nsurfaces,
                 double stiffness, double max_force, double force[3]) {
  return proxy_update_friction(p, device, surfaces, nsurfaces, stiffness, max_force, 0, force);
}

int proxy_update_friction(proxy_t *p, const double device[3], const proxy_surface_t *surfaces, size_t nsurfaces,
                          double stiffness, double max_force, double mu, double force[3]) {
  v3_set(force, 0, 0, 0);
  if (!p->have_prev) {
    v3_copy(p->device_prev, device);
    p->have_prev = 1;
  }
  if (!p->in_contact) {
    if (find_entry(p->device_prev, device, surfaces, nsurfaces, p)) {
      p->in_contact = 1;
      proxy_follow_surface(p, surfaces, nsurfaces);
    }
  } else {
    proxy_follow_surface(p, surfaces, nsurfaces);
  }
  v3_copy(p->device_prev, device);
  if (!p->in_contact) {
    p->surface = -1;
    v3_copy(p->pos, device);
    return 0;
  }
  double d[3];
  v3_sub(d, device, p->pos);
  double depth = v3_dot(d, p->normal);
  /* Released only once clearly above the surface: tissue pushed by the tool
   * can move away faster than a slow hand follows, and a release then
   * would leave the device inside the organ with no entry crossing. */
  if (depth > PROXY_RELEASE_MARGIN) {
    p->in_contact = 0;
    p->surface = -1;
    v3_set(p->settle, 0, 0, 0);
    v3_copy(p->pos, device);
    return 0;
  }
  /* Slide: the device projected on the tangent plane, then back onto the surface. */
  double target[3];
  v3_copy(target, device);
  v3_axpy(target, p->normal, -depth);
  if (mu > 0) {
    /* Friction cone: the spring's tangential part K |target - proxy| against
     * mu times its normal part K (-depth); K cancels. */
    double tang[3];
    v3_sub(tang, target, p->pos);
    v3_axpy(tang, p->normal, -v3_dot(tang, p->normal));
    double dist = v3_norm(tang), cone = mu * fmax(0.0, -depth);
    if (dist <= cone) { /* sticks: stays on its triangle */
      proxy_spring_force(p, device, stiffness, max_force, force);
      return 1;
    }
    v3_copy(target, p->pos);
    v3_axpy(target, tang, (dist - cone) / dist);
  }
  proxy_t before = *p;
  nearest_on_surfaces(target, surfaces, nsurfaces, p);
  proxy_follow_surface(p, surfaces, nsurfaces);
  /* A tool pressed deep into thin tissue brings the far side's surface
   * nearer than the entry side: the god-object never slides onto a surface
   * facing away from the one it is on. It stays on its triangle instead. */
  if (v3_dot(p->normal, before.normal) < 0.2) {
    *p = before;
    const proxy_surface_t *s = &surfaces[p->surface];
    double cp[3];
    tri_closest_point(target, s->x + 3 * s->tris[3 * p->tri], s->x + 3 * s->tris[3 * p->tri + 1],
                      s->x + 3 * s->tris[3 * p->tri + 2], cp, p->bary);
    proxy_follow_surface(p, surfaces, nsurfaces);
  }
  proxy_spring_force(p, device, stiffness, max_force, force);
  return 1;
}

void proxy_settle(proxy_t *p, double dt) {
  if (p->settle[0] == 0 && p->settle[1] == 0 && p->settle[2] == 0) return;
  v3_scale(p->settle, p->settle, exp(-dt / PROXY_SETTLE_TAU));
  if (v3_norm(p->settle) < 1e-9) v3_set(p->settle, 0, 0, 0);
}

double proxy_spring_force(const proxy_t *p, const double device[3], double stiffness, double max_force, double f[3]) {
  if (!p->in_contact) {
    v3_set(f, 0, 0, 0);
    return 0;
  }
  v3_sub(f, p->pos, device);
  if (v3_dot(f, p->normal) <= 0) { /* touching from above: a surface only pushes */
    v3_set(f, 0, 0, 0);
    return 0;
  }
  v3_scale(f, f, stiffness);
  double mag = v3_norm(f);
  if (mag > max_force && mag > 0) {
    v3_scale(f, f, max_force / mag);
    mag = max_force;
  }
  return mag;
}
