/* SPDX-License-Identifier: Apache-2.0 */
/* press_hold.h: press a probe into an organ, hold it, release it, through
 * the real runtime (the fixture of stab_implicit_pcg and
 * stab_coupling_*). The probe comes from 2 mm above the highest rest
 * vertex to 5 mm (press_to: depth) below it over 0.1 s, holds 1 s, is judged over 0.1 s
 * (surface speed from step-to-step displacement, force spread), then is
 * pulled 30 mm up in one step and the run goes on 0.5 s. Header-only. */
#ifndef VISCERA_PRESS_HOLD_H
#define VISCERA_PRESS_HOLD_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "runtime/scene_runtime.h"
#include "vmath.h"

typedef struct press_result {
  int ok, finite, contact, substeps, max_substeps; /* substeps: at the start; max_substeps: the most of any step */
  double speed, force, spread, release_speed0, release_speed_end;
  uint64_t rollbacks;
} press_result_t;

/* Over the first n vertices: a refining model (adaptive_mass_spring)
 * keeps its coarse vertices' indices and appends the new ones. */
static inline double surface_speed(const model_t *m, const double *prev, size_t n, double dt) {
  double vmax = 0;
  if (n > m->nsurf) n = m->nsurf;
  for (size_t i = 0; i < n; i++) vmax = fmax(vmax, v3_dist(m->surf_x + 3 * i, prev + 3 * i) / dt);
  return vmax;
}

static inline int state_finite(const model_t *m) {
  for (size_t c = 0; c < 3 * m->nnodes; c++)
    if (!isfinite(m->x[c]) || !isfinite(m->v[c])) return 0;
  return 1;
}

/* The press to `depth` (m) below the highest rest vertex, with the device's
 * force limit `max_force` (N). */
static inline press_result_t press_to(runtime_t *rt, double depth, double max_force) {
  press_result_t r = {.finite = 1, .contact = 1};
  const model_t *m = rt->organs[0].model;
  r.substeps = m->substeps;
  size_t top = 0;
  for (size_t i = 1; i < m->nsurf; i++)
    if (m->surf_rest[3 * i + 2] > m->surf_rest[3 * top + 2]) top = i;
  double p[3], dt = rt->scene.dt;
  v3_copy(p, m->surf_rest + 3 * top);
  double z0 = p[2] + 0.002, z1 = p[2] - depth;
  long ramp = lround(0.1 / dt), hold = lround(1.0 / dt), window = lround(0.1 / dt), after = lround(0.5 / dt);
  if (ramp < 1) ramp = 1;
  if (window < 2) window = 2;
  size_t cap = m->nsurf, nprev;
  double *prev = malloc(3 * cap * sizeof(double));
  if (!prev) return r;
  double fsum = 0, flo = INFINITY, fhi = 0;
  for (long s = 0; s < ramp + hold + window + after; s++) {
    double a = fmin(1.0, (double)s / (double)ramp);
    p[2] = s < ramp + hold + window ? z0 + a * (z1 - z0) : z1 + 0.03;
    if (m->nsurf > cap) { /* the surface grew (refinement) */
      double *grown = realloc(prev, 3 * m->nsurf * sizeof(double));
      if (!grown) break;
      prev = grown;
      cap = m->nsurf;
    }
    nprev = m->nsurf;
    memcpy(prev, m->surf_x, 3 * nprev * sizeof(double));
    runtime_set_tool(rt, 0, p, max_force);
    runtime_step(rt);
    m = rt->organs[0].model;
    if (m->substeps > r.max_substeps) r.max_substeps = m->substeps;
    if (!state_finite(m)) r.finite = 0;
    double speed = surface_speed(m, prev, nprev, dt);
    if (s >= ramp + hold && s < ramp + hold + window) {
      double f = v3_norm(rt->tools[0].force);
      fsum += f;
      flo = fmin(flo, f);
      fhi = fmax(fhi, f);
      r.speed = fmax(r.speed, speed);
      if (!rt->tools[0].proxy.in_contact) r.contact = 0;
    }
    if (s == ramp + hold + window) r.release_speed0 = speed;
    r.release_speed_end = speed;
  }
  free(prev);
  r.force = fsum / (double)window;
  r.spread = r.force > 0 ? (fhi - flo) / r.force : INFINITY;
  r.rollbacks = rt->organs[0].rollbacks;
  r.ok = r.finite && r.contact && r.rollbacks == 0 && r.speed < 1e-6 && r.spread <= 0.01 && r.force > 0;
  return r;
}

/* 5 mm down, 4 N device. */
static inline press_result_t press(runtime_t *rt) { return press_to(rt, 0.005, 4); }

#endif
