/* SPDX-License-Identifier: Apache-2.0 */
/* ms_cut_fixture: what the cutting unit test and benchmark share: a
 * generated sheet, a mass_spring_surface model from a mesh, a straight
 * blade stroke driven step by step, and mesh validity checks (manifold
 * edges and vertices, orientation, degenerate faces, components).
 * Header-only, static functions; asset meshes load with test_assets.h. */
#ifndef VISCERA_MS_CUT_FIXTURE_H
#define VISCERA_MS_CUT_FIXTURE_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cutting/ms_cut.h"
#include "mesh.h"
#include "mesh_check.h"
#include "mesh_import.h"
#include "physics/model.h"
#include "test_assets.h"
#include "vmath.h"

/* A flat sheet w x h metres at z = 0, nx x ny nodes, centred on the origin,
 * quads split along alternating diagonals, normals +z. */
static inline int fx_sheet(mesh_t *m, int nx, int ny, double w, double h) {
  verr_t err;
  if (mesh_alloc(m, (size_t)nx * ny, 2 * (size_t)(nx - 1) * (ny - 1), &err)) return -1;
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++) {
      double *p = m->pos + 3 * ((size_t)j * nx + i);
      p[0] = -w / 2 + w * i / (nx - 1);
      p[1] = -h / 2 + h * j / (ny - 1);
      p[2] = 0;
    }
  size_t t = 0;
  for (int j = 0; j + 1 < ny; j++)
    for (int i = 0; i + 1 < nx; i++) {
      uint32_t a = (uint32_t)(j * nx + i), b = a + 1, c = a + (uint32_t)nx, d = c + 1;
      uint32_t *f = m->tris + 6 * t++;
      if ((i + j) % 2) {
        uint32_t q[6] = {a, b, d, a, d, c};
        memcpy(f, q, sizeof q);
      } else {
        uint32_t q[6] = {a, b, c, b, d, c};
        memcpy(f, q, sizeof q);
      }
    }
  return 0;
}

typedef struct fx_material {
  double mass, stiffness, damping, home_stiffness, home_damping;
} fx_material_t;

/* The scene defaults (assets/scenes/README.md). */
static const fx_material_t FX_DEFAULT_MATERIAL __attribute__((unused)) = {0.1, 30, 0.02, 30, 0.005};

static inline model_t *fx_model(const mesh_t *mesh, fx_material_t mat, const char *integrator, double dt, verr_t *err) {
  static scene_organ_t cfg; /* the model keeps no pointer to it after create */
  memset(&cfg, 0, sizeof cfg);
  snprintf(cfg.model, sizeof cfg.model, "mass_spring_surface");
  snprintf(cfg.integrator, sizeof cfg.integrator, "%s", integrator);
  cfg.material.mass = mat.mass;
  cfg.material.stiffness = mat.stiffness;
  cfg.material.damping = mat.damping;
  cfg.material.home_stiffness = mat.home_stiffness;
  cfg.material.home_damping = mat.home_damping;
  cfg.solver.cg_tolerance = 1e-3;
  cfg.solver.cg_max_iterations = 200;
  model_params_t p = {.cfg = &cfg, .surface = mesh, .gravity = {0, 0, 0}, .dt = dt, .tool_stiffness = 0};
  return model_create(&p, err);
}

/* A vertical blade (axis from z + 0.02 down to z - 0.02 around the surface
 * height z0) moved in a straight line from a to b (z ignored) at `speed`
 * m/s, one ms_cut_step and one model step per dt, then ms_cut_end. Returns
 * the steps taken, or -1 on error (printed). cut_ms accumulates the wall
 * time of the steps that changed the topology. */
static inline long fx_stroke(model_t *m, ms_cut_t *c, const double a[2], const double b[2], double z0, double radius,
                             double speed, double dt, double *cut_ms, int *topo_changes) {
  double len = hypot(b[0] - a[0], b[1] - a[1]);
  long steps = (long)ceil(len / (speed * dt));
  verr_t err;
  for (long s = 0; s <= steps; s++) {
    double f = steps ? (double)s / steps : 1;
    double x = a[0] + f * (b[0] - a[0]), y = a[1] + f * (b[1] - a[1]);
    double p0[3] = {x, y, z0 + 0.02}, p1[3] = {x, y, z0 - 0.02};
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    int rc = ms_cut_step(c, p0, p1, radius, &err);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (rc < 0) {
      printf("ms_cut_step: %s\n", err.msg);
      return -1;
    }
    if (rc == 1) {
      if (cut_ms) *cut_ms += (t1.tv_sec - t0.tv_sec) * 1e3 + (t1.tv_nsec - t0.tv_nsec) * 1e-6;
      if (topo_changes) (*topo_changes)++;
    }
    m->ops->step(m, dt);
  }
  int rc = ms_cut_end(c, &err);
  if (rc < 0) {
    printf("ms_cut_end: %s\n", err.msg);
    return -1;
  }
  if (rc == 1 && topo_changes) (*topo_changes)++;
  /* The blade lifted away for 20 steps: ms_cut_step keeps being called, as
   * the runtime does, and finishes the stability re-estimate. */
  for (int s = 0; s < 20; s++) {
    double up0[3] = {b[0], b[1], z0 + 1.0}, up1[3] = {b[0], b[1], z0 + 0.9};
    if (ms_cut_step(c, up0, up1, radius, &err) < 0) {
      printf("ms_cut_step: %s\n", err.msg);
      return -1;
    }
    m->ops->step(m, dt);
  }
  return steps + 21;
}

typedef struct fx_check {
  mesh_report_t r;
  size_t nonmanifold_vertices; /* triangles around the vertex form more than one fan */
  size_t nonfinite;
} fx_check_t;

/* The model's surface checked as a mesh. Returns 0 or -1 (OOM). */
static inline int fx_check(const model_t *m, fx_check_t *out) {
  memset(out, 0, sizeof *out);
  mesh_t view = {m->nsurf, m->nsurf_tris, m->surf_x, (uint32_t *)m->surf_tris};
  if (mesh_check(&view, &out->r)) return -1;
  for (size_t c = 0; c < 3 * m->nsurf; c++) out->nonfinite += !isfinite(m->surf_x[c]);
  /* Vertex manifoldness: walk the fan of each vertex through shared edges. */
  size_t nt = m->nsurf_tris;
  uint32_t *inc = malloc((3 * nt + 1) * sizeof *inc), *start = calloc(m->nsurf + 2, sizeof *start);
  uint8_t *seen = calloc(nt + 1, 1);
  if (!inc || !start || !seen) return -1;
  for (size_t k = 0; k < 3 * nt; k++) start[m->surf_tris[k] + 2]++;
  for (size_t i = 0; i < m->nsurf; i++) start[i + 2] += start[i + 1];
  for (size_t k = 0; k < 3 * nt; k++) inc[start[m->surf_tris[k] + 1]++] = (uint32_t)(k / 3);
  for (size_t v = 0; v < m->nsurf; v++) {
    uint32_t b = start[v], e = start[v + 1];
    if (e == b) continue;
    /* Flood from the first triangle through triangles sharing an edge at v. */
    uint32_t stack[256];
    size_t sp = 0, reached = 1;
    seen[inc[b]] = 1;
    stack[sp++] = inc[b];
    while (sp) {
      const uint32_t *f = m->surf_tris + 3 * (size_t)stack[--sp];
      for (uint32_t k = b; k < e; k++) {
        uint32_t t = inc[k];
        if (seen[t]) continue;
        const uint32_t *g = m->surf_tris + 3 * (size_t)t;
        int shared = 0;
        for (int x = 0; x < 3; x++)
          for (int y = 0; y < 3; y++) shared += f[x] == g[y] && f[x] != v;
        if (shared && sp < 256) {
          seen[t] = 1;
          stack[sp++] = t;
          reached++;
        }
      }
    }
    if (reached != e - b) out->nonmanifold_vertices++;
    for (uint32_t k = b; k < e; k++) seen[inc[k]] = 0;
  }
  free(inc);
  free(start);
  free(seen);
  return 0;
}

static inline int fx_valid(const fx_check_t *c) {
  return c->r.nonmanifold_edges == 0 && c->r.inconsistent_edges == 0 && c->r.degenerate_faces == 0 &&
         c->r.unreferenced_vertices == 0 && c->r.bad_index_faces == 0 && c->nonfinite == 0 &&
         c->nonmanifold_vertices == 0;
}

static inline void fx_print(const char *what, const fx_check_t *c) {
  printf("%s: %zu v, %zu t, %zu components, boundary edges %zu, non-manifold edges %zu / vertices %zu, "
         "inconsistent %zu, degenerate %zu, unreferenced %zu, min angle %.1f deg, non-finite %zu\n",
         what, c->r.vertices, c->r.triangles, c->r.components, c->r.boundary_edges, c->r.nonmanifold_edges,
         c->nonmanifold_vertices, c->r.inconsistent_edges, c->r.degenerate_faces, c->r.unreferenced_vertices,
         c->r.min_angle_deg, c->nonfinite);
}

#endif
