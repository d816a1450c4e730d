/* SPDX-License-Identifier: Apache-2.0 */
#include "interaction/stone.h"

#include <math.h>
#include <string.h>

#include "vmath.h"

void stone_init(stone_t *s, double radius, int organ, const double pos[3]) {
  memset(s, 0, sizeof *s);
  s->radius = radius;
  s->organ = organ;
  v3_copy(s->pos, pos);
  s->held_by = -1;
}

double stone_winding_number(const double *x, const uint32_t *tris, size_t ntris, const double p[3]) {
  double sum = 0;
  for (size_t t = 0; t < ntris; t++)
    sum += tri_solid_angle(p, x + 3 * tris[3 * t], x + 3 * tris[3 * t + 1], x + 3 * tris[3 * t + 2]);
  return sum / (4 * 3.14159265358979323846);
}

double stone_surface_distance(const double *x, const uint32_t *tris, size_t ntris, const double p[3]) {
  double best = INFINITY;
  for (size_t t = 0; t < ntris; t++) {
    double q[3], bary[3];
    tri_closest_point(p, x + 3 * tris[3 * t], x + 3 * tris[3 * t + 1], x + 3 * tris[3 * t + 2], q, bary);
    double d = v3_dist(p, q);
    if (d < best) best = d;
  }
  return best;
}

size_t stone_push(stone_t *s, const double *x, size_t nsurf, double k,
                  void (*add)(void *ctx, uint32_t i, const double f[3]), void *ctx) {
  v3_set(s->force, 0, 0, 0);
  size_t n = 0;
  double r2 = s->radius * s->radius;
  for (size_t i = 0; i < nsurf; i++) {
    double d[3];
    v3_sub(d, x + 3 * i, s->pos);
    double dd = v3_dot(d, d);
    if (!(dd < r2)) continue;
    double len = sqrt(dd);
    if (len < 1e-12) continue; /* at the very centre: no direction to push */
    double depth = s->radius - len, mag = fmin(k * depth, STONE_MAX_VERTEX_FORCE), f[3];
    v3_scale(f, d, mag / len);
    add(ctx, (uint32_t)i, f);
    v3_axpy(s->force, f, -1);
    n++;
  }
  return n;
}

int stone_within_reach(const stone_t *s, const double tip[3], double reach) {
  return v3_dist(tip, s->pos) - s->radius <= reach;
}

void stone_grab(stone_t *s, int tool, const double tip[3]) {
  s->held_by = tool;
  v3_sub(s->offset, s->pos, tip);
}

void stone_follow(stone_t *s, const double tip[3]) {
  if (s->held_by >= 0) v3_add(s->pos, tip, s->offset);
}

void stone_release(stone_t *s) { s->held_by = -1; }

int stone_check_removed(stone_t *s, const double *x_rest, const uint32_t *tris, size_t ntris) {
  if (s->removed) return 1;
  if (stone_winding_number(x_rest, tris, ntris, s->pos) < 0.5 &&
      stone_surface_distance(x_rest, tris, ntris, s->pos) > s->radius)
    s->removed = 1;
  return s->removed;
}
