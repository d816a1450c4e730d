/* SPDX-License-Identifier: Apache-2.0 */
#include "physics/vertex_based.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "vmath.h"

static void sort_u32(uint32_t *a, size_t n) {
  /* Rings hold a handful of entries: insertion sort beats qsort's overhead. */
  for (size_t i = 1; i < n; i++) {
    uint32_t key = a[i];
    size_t j = i;
    while (j > 0 && a[j - 1] > key) {
      a[j] = a[j - 1];
      j--;
    }
    a[j] = key;
  }
}

/* Ring 1 from the triangles: every triangle contributes both directions of
 * its three edges; duplicates (an edge seen from its two triangles) are
 * removed after a per-vertex sort. */
static int build_ring1(vb_t *vb, const mesh_t *s) {
  size_t n = vb->n;
  uint32_t *cnt = calloc(n + 1, sizeof(uint32_t));
  uint32_t *tmp = malloc((6 * s->ntris + 1) * sizeof(uint32_t));
  vb->r1_off = calloc(n + 1, sizeof(uint32_t));
  if (!cnt || !tmp || !vb->r1_off) {
    free(cnt);
    free(tmp);
    return -1;
  }
  for (size_t t = 0; t < s->ntris; t++)
    for (int k = 0; k < 3; k++) cnt[s->tris[3 * t + k]] += 2;
  uint32_t *start = calloc(n + 1, sizeof(uint32_t));
  if (!start) {
    free(cnt);
    free(tmp);
    return -1;
  }
  for (size_t i = 0; i < n; i++) start[i + 1] = start[i] + cnt[i];
  memset(cnt, 0, (n + 1) * sizeof(uint32_t));
  for (size_t t = 0; t < s->ntris; t++) {
    const uint32_t *f = s->tris + 3 * t;
    for (int k = 0; k < 3; k++) {
      uint32_t a = f[k], b = f[(k + 1) % 3];
      if (a == b) continue;
      tmp[start[a] + cnt[a]++] = b;
      tmp[start[b] + cnt[b]++] = a;
    }
  }
  /* Unique per vertex, compacted in place into tmp, offsets into r1_off. */
  size_t w = 0;
  for (size_t i = 0; i < n; i++) {
    uint32_t *a = tmp + start[i];
    sort_u32(a, cnt[i]);
    vb->r1_off[i] = (uint32_t)w;
    for (uint32_t k = 0; k < cnt[i]; k++)
      if (k == 0 || a[k] != a[k - 1]) tmp[w++] = a[k];
  }
  vb->r1_off[n] = (uint32_t)w;
  free(cnt);
  free(start);
  vb->r1_idx = realloc(tmp, (w + 1) * sizeof(uint32_t));
  if (!vb->r1_idx) {
    free(tmp);
    return -1;
  }
  return 0;
}

/* Ring 2 = neighbours of ring 1 that are neither the node nor in ring 1
 * (docs/methods.md B §4.2.1, FINDSECONDRINGNEIGHBOUR). A stamp array marks the node
 * and its ring 1, so each vertex costs the sum of its neighbours' valences.
 * Two passes: count, then fill. */
static int build_ring2(vb_t *vb) {
  size_t n = vb->n;
  uint32_t *stamp = malloc((n + 1) * sizeof(uint32_t));
  vb->r2_off = calloc(n + 1, sizeof(uint32_t));
  if (!stamp || !vb->r2_off) {
    free(stamp);
    return -1;
  }
  for (int pass = 0; pass < 2; pass++) {
    for (size_t i = 0; i < n; i++) stamp[i] = UINT32_MAX;
    size_t w = 0;
    for (size_t i = 0; i < n; i++) {
      if (pass == 0) vb->r2_off[i] = (uint32_t)w;
      size_t w0 = w;
      stamp[i] = (uint32_t)i;
      for (uint32_t a = vb->r1_off[i]; a < vb->r1_off[i + 1]; a++) stamp[vb->r1_idx[a]] = (uint32_t)i;
      for (uint32_t a = vb->r1_off[i]; a < vb->r1_off[i + 1]; a++) {
        uint32_t j = vb->r1_idx[a];
        for (uint32_t b = vb->r1_off[j]; b < vb->r1_off[j + 1]; b++) {
          uint32_t k = vb->r1_idx[b];
          if (stamp[k] == (uint32_t)i) continue;
          stamp[k] = (uint32_t)i;
          if (pass == 1) vb->r2_idx[w] = k;
          w++;
        }
      }
      if (pass == 1) sort_u32(vb->r2_idx + w0, w - w0);
    }
    if (pass == 0) {
      vb->r2_off[n] = (uint32_t)w;
      vb->r2_idx = malloc((w + 1) * sizeof(uint32_t));
      if (!vb->r2_idx) {
        free(stamp);
        return -1;
      }
    }
  }
  free(stamp);
  return 0;
}

int vb_create(vb_t *vb, const mesh_t *s, const vb_params_t *p, verr_t *err) {
  memset(vb, 0, sizeof *vb);
  const double *m = p->slope;
  /* The contract orders the slopes as magnitudes, m1 > m2 > m3 > 0. The
   * thesis writes them negative in (-1, 0) with m1 > m2 > m3 (its F is the
   * device's reaction); read literally that would move ring 2 most, against
   * its own Fig. 4.2, so magnitudes are what is meant. */
  if (!(isfinite(m[0]) && m[0] > m[1] && m[1] > m[2] && m[2] > 0))
    return verr_set(err, "vertex_based: slopes must satisfy m1 > m2 > m3 > 0 (got %g, %g, %g)", m[0], m[1], m[2]);
  if (!(p->home_stiffness > 0) || !isfinite(p->home_stiffness))
    return verr_set(err, "vertex_based: home_stiffness must be > 0 (the indentation is F / home_stiffness), got %g",
                    p->home_stiffness);
  if (!(p->mass > 0) || !isfinite(p->mass) || !(p->home_damping >= 0) || !isfinite(p->home_damping) ||
      !(p->tool_stiffness >= 0))
    return verr_set(err, "vertex_based: mass must be > 0, home_damping and tool stiffness >= 0");
  if (s->nverts == 0 || s->nverts >= UINT32_MAX || s->ntris == 0)
    return verr_set(err, "vertex_based: mesh has no triangles");
  if (mesh_validate(s, "vertex_based surface", err)) return -1;
  size_t n = s->nverts;
  vb->n = n;
  vb->p = *p;
  vb->node_mass = p->mass / (double)n;
  vb->x = malloc(3 * n * sizeof(double));
  vb->v = calloc(3 * n, sizeof(double));
  vb->x_rest = malloc(3 * n * sizeof(double));
  vb->fixed = calloc(n, 1);
  vb->active = malloc(n * sizeof(uint32_t));
  vb->is_active = calloc(n, 1);
  int guard_rc = model_guard_reserve(&vb->guard, n);
  if (!vb->x || !vb->v || !vb->x_rest || !vb->fixed || !vb->active || !vb->is_active || guard_rc ||
      build_ring1(vb, s) || build_ring2(vb)) {
    vb_destroy(vb);
    return verr_set(err, "vertex_based: out of memory for %zu vertices", n);
  }
  memcpy(vb->x, s->pos, 3 * n * sizeof(double));
  memcpy(vb->x_rest, s->pos, 3 * n * sizeof(double));
  /* Snap thresholds relative to the mesh scale: 1e-7 of the mean edge is far
   * below the publisher's quantisation, so snapping home is invisible. */
  double sum = 0;
  for (size_t i = 0; i < n; i++)
    for (uint32_t a = vb->r1_off[i]; a < vb->r1_off[i + 1]; a++)
      sum += v3_dist(s->pos + 3 * i, s->pos + 3 * (size_t)vb->r1_idx[a]);
  double mean_edge = vb->r1_off[n] ? sum / vb->r1_off[n] : 1e-3;
  vb->eps_x = 1e-7 * (mean_edge > 0 ? mean_edge : 1e-3);
  vb->eps_v = vb->eps_x / 1e-3;
  vb->touched = vb->last_touched = UINT32_MAX;
  return 0;
}

void vb_destroy(vb_t *vb) {
  free(vb->x);
  free(vb->v);
  free(vb->x_rest);
  free(vb->fixed);
  free(vb->r1_off);
  free(vb->r1_idx);
  free(vb->r2_off);
  free(vb->r2_idx);
  free(vb->active);
  free(vb->is_active);
  model_guard_free(&vb->guard);
  memset(vb, 0, sizeof *vb);
}

size_t vb_fix_below(vb_t *vb, double z) {
  size_t count = 0;
  for (size_t i = 0; i < vb->n; i++)
    if (vb->x_rest[3 * i + 2] < z) {
      vb->fixed[i] = 1;
      count++;
    }
  return count;
}

double vb_stable_dt(const vb_t *vb) {
  /* Touched node, tool spring g explicit, home spring (k, c) implicit: the
   * update matrix has det m / (m + h c + h^2 k) < 1 and trace condition
   * h^2 (g - k) - 2 h c - 4 m < 0 (Jury test). */
  double m = vb->node_mass, k = vb->p.home_stiffness, c = vb->p.home_damping;
  double g = vb->p.slope[0] * vb->p.tool_stiffness;
  if (g <= k) return INFINITY;
  return (c + sqrt(c * c + 4 * m * (g - k))) / (g - k);
}

void vb_add_coupling(vb_t *vb, double k) {
  if (k > 0 && isfinite(k)) vb->coupling_k += k;
}

void vb_add_force(vb_t *vb, uint32_t i, const double f[3]) {
  if (i >= vb->n) return;
  v3_add(vb->f_sum, vb->f_sum, f);
  double mag = v3_norm(f);
  /* `!(mag <= ...)` also takes a NaN force, so a corrupt sample reaches the
   * state and is caught by the finiteness check instead of being dropped. */
  if (vb->touched == UINT32_MAX || !(mag <= vb->touched_mag)) {
    vb->touched = i;
    vb->touched_mag = mag;
  }
}

static inline void activate(vb_t *vb, uint32_t i) {
  if (vb->is_active[i] || vb->fixed[i]) return;
  vb->is_active[i] = 1;
  vb->active[vb->nactive++] = i;
}

/* Backward Euler for m a = k (P - x) - c v with P = x_rest + d: the spring
 * and damper are evaluated at the end of the step, which for one linear
 * node is a division (unconditionally stable, damps like implicit Euler). */
static inline void integrate(vb_t *vb, uint32_t i, const double d[3], double h, double denom) {
  double m = vb->node_mass, k = vb->p.home_stiffness;
  double *x = vb->x + 3 * i, *v = vb->v + 3 * i;
  const double *xr = vb->x_rest + 3 * i;
  for (int c = 0; c < 3; c++) {
    double u = x[c] - xr[c];
    v[c] = (m * v[c] + h * k * (d[c] - u)) / denom;
    x[c] += h * v[c];
  }
}

/* One sub-step: the touched node and its rings are driven towards eq.
 * 4.2-4.4, every other active node towards home (eq. 4.11). */
static void substep(vb_t *vb, double h) {
  double denom = vb->node_mass + h * vb->p.home_damping + h * h * vb->p.home_stiffness;
  static const double zero[3] = {0, 0, 0};
  uint32_t t = vb->touched;
  size_t updates = 0;
  if (t != UINT32_MAX) {
    /* u = F / k_home: the indentation the home spring alone would take. */
    double u[3], d[3];
    v3_scale(u, vb->f_sum, 1.0 / vb->p.home_stiffness);
    /* Rings first: activating them puts them in the active list, and a
     * stamp would be needed to skip them below; instead they are integrated
     * here and the active pass skips nodes with this sub-step's mark. */
    size_t n1, n2;
    const uint32_t *r1 = vb_ring1(vb, t, &n1), *r2 = vb_ring2(vb, t, &n2);
    if (!vb->fixed[t]) {
      activate(vb, t);
      v3_scale(d, u, vb->p.slope[0]);
      /* d = slope_m1 F / k_home with F = F0 - g h v' (the declared tool
       * springs at the step's end): h^2 slope_m1 g joins the denominator. */
      integrate(vb, t, d, h, denom + h * h * vb->p.slope[0] * vb->coupling_k);
      vb->is_active[t] = 2;
      updates++;
    }
    v3_scale(d, u, vb->p.slope[1]);
    for (size_t a = 0; a < n1; a++) {
      if (vb->fixed[r1[a]]) continue;
      activate(vb, r1[a]);
      integrate(vb, r1[a], d, h, denom);
      vb->is_active[r1[a]] = 2;
    }
    v3_scale(d, u, vb->p.slope[2]);
    for (size_t a = 0; a < n2; a++) {
      if (vb->fixed[r2[a]]) continue;
      activate(vb, r2[a]);
      integrate(vb, r2[a], d, h, denom);
      vb->is_active[r2[a]] = 2;
    }
    updates += n1 + n2;
    vb->last_touched = t;
  }
  for (size_t a = 0; a < vb->nactive; a++) {
    uint32_t i = vb->active[a];
    if (vb->is_active[i] == 2) {
      vb->is_active[i] = 1; /* done above; clear the mark */
      continue;
    }
    integrate(vb, i, zero, h, denom);
    updates++;
  }
  vb->last_node_updates += updates;
  v3_set(vb->f_sum, 0, 0, 0);
  vb->touched = UINT32_MAX;
  vb->touched_mag = 0;
}

int vb_step(vb_t *vb, double h, int substeps, vb_pre_fn pre, void *ctx) {
  /* Save only the active nodes: nodes activated during the step were at
   * home with zero velocity, which is what rollback restores them to. */
  size_t n0 = vb->nactive;
  model_guard_save(&vb->guard, vb->x, vb->v, n0, vb->active);
  if (substeps < 1) substeps = 1;
  double hs = h / substeps;
  vb->last_node_updates = 0;
  vb->last_touched = UINT32_MAX;
  for (int s = 0; s < substeps; s++) {
    v3_set(vb->f_sum, 0, 0, 0);
    vb->touched = UINT32_MAX;
    vb->touched_mag = 0;
    vb->coupling_k = 0;
    if (pre) pre(ctx);
    substep(vb, hs);
  }
  /* Activation appends: the first n0 active nodes are the saved ones. */
  if (model_guard_check(&vb->guard, vb->x, vb->v, vb->nactive, vb->active, NULL)) {
    for (size_t a = n0; a < vb->nactive; a++) {
      uint32_t i = vb->active[a];
      memcpy(vb->x + 3 * i, vb->x_rest + 3 * i, 3 * sizeof(double));
      v3_set(vb->v + 3 * i, 0, 0, 0);
      vb->is_active[i] = 0;
    }
    vb->nactive = n0;
    return -1;
  }
  if (vb->nactive > vb->max_active) vb->max_active = vb->nactive;
  /* Retire nodes that are home: snap exactly (no drift accumulates) and
   * drop them, so the next step's cost is the live neighbourhood only. */
  for (size_t a = 0; a < vb->nactive;) {
    uint32_t i = vb->active[a];
    double *x = vb->x + 3 * i, *v = vb->v + 3 * i;
    const double *xr = vb->x_rest + 3 * i;
    double du = fmax(fabs(x[0] - xr[0]), fmax(fabs(x[1] - xr[1]), fabs(x[2] - xr[2])));
    double dv = fmax(fabs(v[0]), fmax(fabs(v[1]), fabs(v[2])));
    if (du < vb->eps_x && dv < vb->eps_v) {
      v3_copy(x, xr);
      v3_set(v, 0, 0, 0);
      vb->is_active[i] = 0;
      vb->active[a] = vb->active[--vb->nactive];
    } else {
      a++;
    }
  }
  return 0;
}

double vb_energy(const vb_t *vb) {
  double e = 0;
  for (size_t a = 0; a < vb->nactive; a++) {
    uint32_t i = vb->active[a];
    double d[3];
    v3_sub(d, vb->x + 3 * i, vb->x_rest + 3 * i);
    e += 0.5 * vb->node_mass * v3_dot(vb->v + 3 * i, vb->v + 3 * i) + 0.5 * vb->p.home_stiffness * v3_dot(d, d);
  }
  return e;
}

double vb_max_edge_strain(const vb_t *vb) {
  double worst = 0;
  for (size_t a = 0; a < vb->nactive; a++) {
    uint32_t i = vb->active[a];
    for (uint32_t b = vb->r1_off[i]; b < vb->r1_off[i + 1]; b++) {
      uint32_t j = vb->r1_idx[b];
      double l0 = v3_dist(vb->x_rest + 3 * i, vb->x_rest + 3 * (size_t)j);
      if (!(l0 > 0)) continue;
      double e = fabs(v3_dist(vb->x + 3 * i, vb->x + 3 * (size_t)j) / l0 - 1);
      if (e > worst) worst = e;
    }
  }
  return worst;
}
