/* SPDX-License-Identifier: Apache-2.0 */
#include "interaction/grasp.h"

#include <math.h>
#include <string.h>

#include "vmath.h"

void grasp_init(grasp_t *g) {
  memset(g, 0, sizeof *g);
  g->organ = -1;
}

void grasp_release(grasp_t *g) { grasp_init(g); }

size_t grasp_take(grasp_t *g, int organ, const double *x, size_t nsurf, const double tip[3], double radius) {
  grasp_init(g);
  if (!(radius > 0)) return 0;
  double d[GRASP_MAX_VERTS];
  size_t n = 0;
  for (size_t i = 0; i < nsurf; i++) {
    double di = v3_dist(x + 3 * i, tip);
    if (!(di <= radius)) continue;
    /* Keep the nearest GRASP_MAX_VERTS: replace the farthest kept. */
    size_t slot = n;
    if (n == GRASP_MAX_VERTS) {
      size_t far = 0;
      for (size_t j = 1; j < n; j++)
        if (d[j] > d[far]) far = j;
      if (d[far] <= di) continue;
      slot = far;
    } else {
      n++;
    }
    g->v[slot] = (uint32_t)i;
    d[slot] = di;
  }
  if (n == 0) return 0;
  double sum = 0;
  for (size_t j = 0; j < n; j++) {
    /* The smooth kernel the contact patch uses; a floor keeps a vertex at
     * the rim from carrying no load at all. */
    double a = 1 - d[j] / radius;
    g->w[j] = fmax(a * a, 1e-3);
    sum += g->w[j];
    v3_sub(g->offset[j], x + 3 * g->v[j], tip);
  }
  for (size_t j = 0; j < n; j++) g->w[j] /= sum;
  g->n = n;
  g->organ = organ;
  g->active = 1;
  v3_copy(g->anchor, tip);
  return n;
}

double grasp_force(const grasp_t *g, const double *x, const double tip[3], double k, double max_force, double fv[][3],
                   double f_tool[3]) {
  v3_set(f_tool, 0, 0, 0);
  if (!g->active) return 0;
  double total[3] = {0, 0, 0};
  for (size_t j = 0; j < g->n; j++) {
    double target[3];
    v3_add(target, tip, g->offset[j]);
    v3_sub(fv[j], target, x + 3 * g->v[j]);
    v3_scale(fv[j], fv[j], k * g->w[j]);
    v3_add(total, total, fv[j]);
  }
  double mag = v3_norm(total), s = 1;
  /* A clamp on the sum, not per vertex: the patch keeps its shape while the
   * hand feels at most what the device can render. */
  if (mag > max_force && mag > 0) s = max_force / mag;
  if (!isfinite(mag)) s = 0;
  for (size_t j = 0; j < g->n; j++) v3_scale(fv[j], fv[j], s);
  v3_scale(f_tool, total, -s);
  return mag * s;
}

void grasp_patch_centre(const grasp_t *g, const double *x, double c[3]) {
  v3_set(c, 0, 0, 0);
  for (size_t j = 0; j < g->n; j++) v3_axpy(c, x + 3 * g->v[j], g->w[j]);
}
