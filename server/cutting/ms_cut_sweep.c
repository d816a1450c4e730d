/* SPDX-License-Identifier: Apache-2.0 */
#include "cutting/ms_cut_sweep.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "vmath.h"

static double clamp01(double t) { return t < 0 ? 0 : t > 1 ? 1 : t; }

double ms_sweep_seg_seg_dist(const double a0[3], const double a1[3], const double b0[3], const double b1[3]) {
  /* Closest points a0 + s d1, b0 + t d2 minimising the distance, s, t in
   * [0, 1]: the unconstrained minimiser, clamped one parameter at a time. */
  double d1[3], d2[3], r[3];
  v3_sub(d1, a1, a0);
  v3_sub(d2, b1, b0);
  v3_sub(r, a0, b0);
  double a = v3_dot(d1, d1), e = v3_dot(d2, d2), f = v3_dot(d2, r);
  const double tiny = 1e-300;
  double s, t;
  if (a <= tiny && e <= tiny) return v3_dist(a0, b0);
  if (a <= tiny) {
    s = 0;
    t = clamp01(f / e);
  } else {
    double c = v3_dot(d1, r);
    if (e <= tiny) {
      t = 0;
      s = clamp01(-c / a);
    } else {
      double b = v3_dot(d1, d2), den = a * e - b * b;
      /* Parallel segments (den ~ 0): any s works; take 0 and let t decide. */
      s = den > 1e-12 * a * e ? clamp01((b * f - c * e) / den) : 0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = clamp01(-c / a);
      } else if (t > 1) {
        t = 1;
        s = clamp01((b - c) / a);
      }
    }
  }
  double p[3], q[3];
  v3_copy(p, a0);
  v3_axpy(p, d1, s);
  v3_copy(q, b0);
  v3_axpy(q, d2, t);
  return v3_dist(p, q);
}

double ms_sweep_seg_path_dist(const double a[3], const double b[3], const double *path, size_t npath) {
  if (npath == 0) return INFINITY;
  if (npath == 1) return ms_sweep_seg_seg_dist(a, b, path, path);
  double d = INFINITY;
  for (size_t i = 0; i + 1 < npath; i++) {
    double di = ms_sweep_seg_seg_dist(a, b, path + 3 * i, path + 3 * i + 3);
    if (di < d) d = di;
  }
  return d;
}

double ms_sweep_point_path_dist(const double p[3], const double *path, size_t npath) {
  return ms_sweep_seg_path_dist(p, p, path, npath);
}

void ms_sweep_mark(size_t n, const double *x, size_t ntris, const uint32_t *tris, const double *path, size_t npath,
                   double r, const uint32_t *hit_tris, size_t nhit, uint8_t *node_in, uint8_t *tri_dead) {
  /* Broad phase: the path's box grown by r holds the whole region. */
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < npath; i++)
    for (int k = 0; k < 3; k++) {
      lo[k] = fmin(lo[k], path[3 * i + k] - r);
      hi[k] = fmax(hi[k], path[3 * i + k] + r);
    }
  for (size_t i = 0; i < n; i++) {
    const double *p = x + 3 * i;
    int box = p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1] && p[2] >= lo[2] && p[2] <= hi[2];
    node_in[i] = box && ms_sweep_point_path_dist(p, path, npath) < r;
  }
  for (size_t t = 0; t < ntris; t++) {
    const uint32_t *f = tris + 3 * t;
    tri_dead[t] = node_in[f[0]] || node_in[f[1]] || node_in[f[2]];
    if (tri_dead[t]) continue;
    for (int k = 0; k < 3 && !tri_dead[t]; k++) {
      const double *a = x + 3 * (size_t)f[k], *b = x + 3 * (size_t)f[(k + 1) % 3];
      int out = 0;
      for (int d = 0; d < 3; d++) out |= fmax(a[d], b[d]) < lo[d] || fmin(a[d], b[d]) > hi[d];
      if (!out && ms_sweep_seg_path_dist(a, b, path, npath) < r) tri_dead[t] = 1;
    }
  }
  for (size_t h = 0; h < nhit; h++)
    if (hit_tris[h] < ntris) tri_dead[hit_tris[h]] = 1;
}

typedef struct adj {
  uint32_t *start; /* n + 1 */
  uint32_t *tri;   /* 3 ntris */
} adj_t;

static int adj_build(adj_t *a, size_t n, size_t ntris, const uint32_t *tris) {
  a->start = calloc(n + 2, sizeof(uint32_t));
  a->tri = malloc(3 * ntris * sizeof(uint32_t) + 1);
  if (!a->start || !a->tri) return -1;
  for (size_t c = 0; c < 3 * ntris; c++) a->start[tris[c] + 1]++;
  for (size_t i = 0; i < n; i++) a->start[i + 1] += a->start[i];
  uint32_t *fill = malloc((n + 1) * sizeof(uint32_t));
  if (!fill) return -1;
  memcpy(fill, a->start, (n + 1) * sizeof(uint32_t));
  for (size_t c = 0; c < 3 * ntris; c++) a->tri[fill[tris[c]]++] = (uint32_t)(c / 3);
  free(fill);
  return 0;
}

/* The triangle holding directed edge u -> v, or -1. */
static long tri_with_edge(const adj_t *a, const uint32_t *tris, uint32_t u, uint32_t v) {
  for (uint32_t k = a->start[u]; k < a->start[u + 1]; k++) {
    const uint32_t *f = tris + 3 * (size_t)a->tri[k];
    for (int e = 0; e < 3; e++)
      if (f[e] == u && f[(e + 1) % 3] == v) return (long)a->tri[k];
  }
  return -1;
}

int ms_sweep_cleanup(size_t n, size_t ntris, const uint32_t *tris, uint8_t *tri_dead, ms_sweep_out_t *out,
                     verr_t *err) {
  memset(out, 0, sizeof *out);
  for (size_t c = 0; c < 3 * ntris; c++)
    if (tris[c] >= n) return verr_set(err, "cutting: triangle %zu names node %u of %zu", c / 3, tris[c], n);
  adj_t a = {0};
  uint8_t *hole_out = calloc(n + 1, 1), *hole_in = calloc(n + 1, 1);
  uint32_t *alive = calloc(n + 1, sizeof(uint32_t));
  out->node_dead = calloc(n + 1, 1);
  int rc = -1;
  if (!hole_out || !hole_in || !alive || !out->node_dead || adj_build(&a, n, ntris, tris)) goto out;
  for (int changed = 1; changed;) {
    changed = 0;
    /* Surviving triangles that would stick into the hole. */
    for (size_t t = 0; t < ntris; t++) {
      if (tri_dead[t]) continue;
      const uint32_t *f = tris + 3 * t;
      int dead_twin = 0, live_twin = 0;
      for (int e = 0; e < 3; e++) {
        long tw = tri_with_edge(&a, tris, f[(e + 1) % 3], f[e]);
        if (tw >= 0) {
          if (tri_dead[tw])
            dead_twin++;
          else
            live_twin++;
        }
      }
      if (dead_twin >= 2 || (dead_twin >= 1 && live_twin == 0)) {
        tri_dead[t] = 1;
        changed = 1;
      }
    }
    /* Pinches: a node the hole boundary reaches twice (leaving it twice, or
     * arriving twice: the hole touches an existing boundary node from two
     * sides). */
    memset(hole_out, 0, n);
    memset(hole_in, 0, n);
    for (size_t t = 0; t < ntris; t++) {
      if (!tri_dead[t]) continue;
      const uint32_t *f = tris + 3 * t;
      for (int e = 0; e < 3; e++) {
        long tw = tri_with_edge(&a, tris, f[(e + 1) % 3], f[e]);
        if (tw >= 0 && !tri_dead[tw]) {
          if (hole_out[f[e]] < 255) hole_out[f[e]]++;
          if (hole_in[f[(e + 1) % 3]] < 255) hole_in[f[(e + 1) % 3]]++;
        }
      }
    }
    for (size_t i = 0; i < n; i++) {
      if (hole_out[i] < 2 && hole_in[i] < 2) continue;
      for (uint32_t k = a.start[i]; k < a.start[i + 1]; k++)
        if (!tri_dead[a.tri[k]]) {
          tri_dead[a.tri[k]] = 1;
          changed = 1;
        }
    }
  }
  size_t cap_hole = 16, cap_cut = 16;
  out->hole = malloc(2 * cap_hole * sizeof(uint32_t));
  out->cut = malloc(2 * cap_cut * sizeof(uint32_t));
  if (!out->hole || !out->cut) goto out;
  for (size_t t = 0; t < ntris; t++) {
    const uint32_t *f = tris + 3 * t;
    if (!tri_dead[t]) {
      for (int e = 0; e < 3; e++) alive[f[e]]++;
      continue;
    }
    out->tris_dead++;
    for (int e = 0; e < 3; e++) {
      uint32_t u = f[e], v = f[(e + 1) % 3];
      long tw = tri_with_edge(&a, tris, v, u);
      int hole = tw >= 0 && !tri_dead[tw];
      int cut = tw < 0 || (tri_dead[tw] && u < v);
      if (hole) {
        if (out->nhole == cap_hole) {
          uint32_t *p = realloc(out->hole, 4 * cap_hole * sizeof(uint32_t));
          if (!p) goto out;
          out->hole = p;
          cap_hole *= 2;
        }
        out->hole[2 * out->nhole] = u;
        out->hole[2 * out->nhole++ + 1] = v;
      } else if (cut) {
        if (out->ncut == cap_cut) {
          uint32_t *p = realloc(out->cut, 4 * cap_cut * sizeof(uint32_t));
          if (!p) goto out;
          out->cut = p;
          cap_cut *= 2;
        }
        out->cut[2 * out->ncut] = u;
        out->cut[2 * out->ncut++ + 1] = v;
      }
    }
  }
  for (size_t i = 0; i < n; i++) {
    out->node_dead[i] = alive[i] == 0;
    out->nodes_dead += out->node_dead[i];
  }
  rc = 0;
out:
  free(a.start);
  free(a.tri);
  free(hole_out);
  free(hole_in);
  free(alive);
  if (rc) {
    ms_sweep_out_free(out);
    return verr_set(err, "cutting: out of memory");
  }
  return 0;
}

void ms_sweep_out_free(ms_sweep_out_t *o) {
  free(o->node_dead);
  free(o->hole);
  free(o->cut);
  memset(o, 0, sizeof *o);
}
