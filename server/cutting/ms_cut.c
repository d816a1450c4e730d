/* SPDX-License-Identifier: Apache-2.0 */
#include "cutting/ms_cut.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cutting/bezier.h"
#include "cutting/ms_cut_sweep.h"
#include "cutting/node_match.h"
#include "vmath.h"

#define MS_CUT_REFINE_ITERATIONS 4 /* power iterations per step after a topology change */

typedef struct lip {
  int side;
  size_t len;
  uint32_t *nodes;
} lip_t;

struct ms_cut {
  model_t *m;
  const model_edit_ops_t *edit; /* m's topology edits (model.h, MODEL_EDIT_SURFACE) */
  ms_cut_params_t p;
  ms_cut_stats_t st;
  double h_mean, l_max; /* rest edge lengths of the uncut model, m */
  double m0;            /* per-node mass of the uncut model, kg */
  /* Node -> triangle adjacency of the current topology (lazy). */
  uint32_t *adj_start, *adj_tri;
  size_t adj_n_cap, adj_t_cap;
  uint32_t adj_version;
  int adj_valid;
  /* The path of the current cut since its last processed segment. */
  int active;
  double radius; /* largest blade radius of the current cut */
  size_t npath, path_cap;
  double *px, *pr;       /* 3 per sample: current and rest position */
  uint32_t *ptri;        /* triangle crossed (UINT32_MAX: from before a topology change) */
  uint32_t path_version; /* topology_version the ptri indices refer to */
  double seg_len_acc;
  lip_t *lips;
  size_t nlips, lip_cap;
};

ms_cut_params_t ms_cut_default_params(void) {
  return (ms_cut_params_t){.eps_r = 0.1, .segment_length = 0, .min_radius_rel = 0.3, .max_radius = 0.02};
}

static double now_ms(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* The model's nodes now (reserve may move the arrays). */
static model_nodes_t nodes(const ms_cut_t *c) {
  model_nodes_t nv;
  c->edit->nodes(c->m, &nv);
  return nv;
}

ms_cut_t *ms_cut_create(model_t *m, const ms_cut_params_t *p, verr_t *err) {
  const model_edit_ops_t *edit = m && m->ops ? m->ops->edit : NULL;
  if (!edit || edit->kind != MODEL_EDIT_SURFACE) {
    verr_set(err, "cutting: model '%s' cannot be cut (three-stage cutting needs mass_spring_surface)",
             m && m->ops ? m->ops->name : "(none)");
    return NULL;
  }
  ms_cut_params_t q = p ? *p : ms_cut_default_params();
  if (!(q.eps_r >= 0 && q.eps_r < 1) || !(q.segment_length >= 0) || !isfinite(q.segment_length) ||
      !(q.min_radius_rel >= 0 && q.min_radius_rel <= 2) || !(q.max_radius > 0) || !isfinite(q.max_radius)) {
    verr_set(err,
             "cutting: eps_r must be in [0, 1), segment_length >= 0, min_radius_rel in [0, 2], max_radius > 0 "
             "(got %g, %g, %g, %g)",
             q.eps_r, q.segment_length, q.min_radius_rel, q.max_radius);
    return NULL;
  }
  double h_mean, l_max;
  if (edit->rest_edges(m, &h_mean, &l_max) == 0 || m->nsurf_tris == 0) {
    verr_set(err, "cutting: the model has no springs or triangles");
    return NULL;
  }
  /* The stability bound's dominant vectors, for quick re-estimates after
   * each cut (model.h edit->prepare): computed now, at scene load. */
  if (edit->prepare && edit->prepare(m, err)) return NULL;
  ms_cut_t *c = calloc(1, sizeof *c);
  if (!c) {
    verr_set(err, "cutting: out of memory");
    return NULL;
  }
  c->m = m;
  c->edit = edit;
  c->p = q;
  c->h_mean = h_mean;
  c->l_max = l_max;
  model_nodes_t nv = nodes(c);
  c->m0 = nv.mass_total / (double)nv.n;
  if (c->p.segment_length == 0) c->p.segment_length = 4 * c->h_mean;
  return c;
}

void ms_cut_destroy(ms_cut_t *c) {
  if (!c) return;
  free(c->adj_start);
  free(c->adj_tri);
  free(c->px);
  free(c->pr);
  free(c->ptri);
  for (size_t i = 0; i < c->nlips; i++) free(c->lips[i].nodes);
  free(c->lips);
  free(c);
}

int ms_cut_active(const ms_cut_t *c) { return c->active; }
const ms_cut_stats_t *ms_cut_stats(const ms_cut_t *c) { return &c->st; }

size_t ms_cut_bytes(const ms_cut_t *c) {
  size_t b = (c->adj_n_cap + 1) * sizeof(uint32_t) * (c->adj_start != NULL) +
             3 * c->adj_t_cap * sizeof(uint32_t) * (c->adj_tri != NULL) + c->path_cap * (6 * sizeof(double) + 4) +
             c->lip_cap * sizeof(lip_t);
  for (size_t i = 0; i < c->nlips; i++) b += c->lips[i].len * sizeof(uint32_t);
  model_nodes_t nv = nodes(c);
  if (nv.f_res) b += 3 * nv.cap * sizeof(double);
  b += 6 * nv.cap * sizeof(double); /* the model's dominant vectors (edit->prepare) */
  return b;
}

/* Node -> triangle adjacency of the current surface; rebuilt after a
 * topology change, arrays grown only when the mesh grew. */
static int adj_update(ms_cut_t *c, verr_t *err) {
  if (c->adj_valid && c->adj_version == c->m->topology_version) return 0;
  size_t n = nodes(c).n, nt = c->m->nsurf_tris;
  if (!c->adj_start || n > c->adj_n_cap) {
    uint32_t *p = realloc(c->adj_start, (n + 2) * sizeof *p);
    if (!p) return verr_set(err, "cutting: out of memory");
    c->adj_start = p;
    c->adj_n_cap = n;
  }
  if (!c->adj_tri || nt > c->adj_t_cap) {
    uint32_t *p = realloc(c->adj_tri, (3 * nt + 1) * sizeof *p);
    if (!p) return verr_set(err, "cutting: out of memory");
    c->adj_tri = p;
    c->adj_t_cap = nt;
  }
  const uint32_t *tris = c->m->surf_tris;
  memset(c->adj_start, 0, (n + 2) * sizeof(uint32_t));
  for (size_t k = 0; k < 3 * nt; k++) c->adj_start[tris[k] + 2]++;
  for (size_t i = 0; i < n; i++) c->adj_start[i + 2] += c->adj_start[i + 1];
  /* adj_start[i + 1] is the fill cursor of node i; after filling it has
   * moved to the end of node i's run = the start of node i + 1. */
  for (size_t k = 0; k < 3 * nt; k++) c->adj_tri[c->adj_start[tris[k] + 1]++] = (uint32_t)(k / 3);
  c->adj_version = c->m->topology_version;
  c->adj_valid = 1;
  return 0;
}

/* Where the blade axis p0 -> p1 first crosses the surface (nearest p0).
 * Returns 1 and the point (current, rest) and triangle, 0 if it does not
 * cross, -1 on OOM. */
static int find_crossing(ms_cut_t *c, const double p0[3], const double p1[3], double r, double x[3], double xr[3],
                         uint32_t *tri, verr_t *err) {
  const model_nodes_t nv = nodes(c);
  const double *X = nv.x;
  size_t n = nv.n;
  /* A crossed triangle has every vertex within its longest edge of the
   * crossing point, which is on the axis: scan nodes near the axis (with a
   * margin for stretched edges). */
  double R = r + 1.5 * c->l_max, lo[3], hi[3];
  for (int k = 0; k < 3; k++) {
    lo[k] = fmin(p0[k], p1[k]) - R;
    hi[k] = fmax(p0[k], p1[k]) + R;
  }
  double best_t = INFINITY;
  int found = 0;
  for (size_t i = 0; i < n; i++) {
    const double *q = X + 3 * i;
    if (q[0] < lo[0] || q[0] > hi[0] || q[1] < lo[1] || q[1] > hi[1] || q[2] < lo[2] || q[2] > hi[2]) continue;
    if (ms_sweep_seg_seg_dist(q, q, p0, p1) >= R) continue;
    if (adj_update(c, err)) return -1;
    for (uint32_t k = c->adj_start[i]; k < c->adj_start[i + 1]; k++) {
      uint32_t t = c->adj_tri[k];
      const uint32_t *f = c->m->surf_tris + 3 * (size_t)t;
      double tt, bary[3];
      if (!seg_tri_intersect(p0, p1, X + 3 * (size_t)f[0], X + 3 * (size_t)f[1], X + 3 * (size_t)f[2], &tt, bary))
        continue;
      if (tt < best_t) {
        best_t = tt;
        found = 1;
        *tri = t;
        for (int d = 0; d < 3; d++) {
          x[d] = xr[d] = 0;
          for (int v = 0; v < 3; v++) {
            x[d] += bary[v] * X[3 * (size_t)f[v] + d];
            xr[d] += bary[v] * nv.x_rest[3 * (size_t)f[v] + d];
          }
        }
      }
    }
  }
  return found;
}

static int path_push(ms_cut_t *c, const double x[3], const double xr[3], uint32_t tri, verr_t *err) {
  if (c->npath == c->path_cap) {
    size_t cap = c->path_cap ? 2 * c->path_cap : 64;
    double *a = realloc(c->px, 3 * cap * sizeof(double));
    if (!a) return verr_set(err, "cutting: out of memory");
    c->px = a;
    double *b = realloc(c->pr, 3 * cap * sizeof(double));
    if (!b) return verr_set(err, "cutting: out of memory");
    c->pr = b;
    uint32_t *t = realloc(c->ptri, cap * sizeof(uint32_t));
    if (!t) return verr_set(err, "cutting: out of memory");
    c->ptri = t;
    c->path_cap = cap;
  }
  v3_copy(c->px + 3 * c->npath, x);
  v3_copy(c->pr + 3 * c->npath, xr);
  c->ptri[c->npath++] = tri;
  return 0;
}

static int lips_push(ms_cut_t *c, int side, size_t len, uint32_t *nodes) {
  if (c->nlips == c->lip_cap) {
    size_t cap = c->lip_cap ? 2 * c->lip_cap : 8;
    lip_t *p = realloc(c->lips, cap * sizeof *p);
    if (!p) return -1;
    c->lips = p;
    c->lip_cap = cap;
  }
  c->lips[c->nlips++] = (lip_t){side, len, nodes};
  return 0;
}

/* The three stages on the path samples [0, npath) and the rebuild. Returns
 * 1 (topology changed), 0 (nothing to cut), -1 (err; model unchanged). */
static int process_segment(ms_cut_t *c, verr_t *err) {
  const double merge_tol = 0.5 * c->h_mean;
  double len = 0;
  for (size_t i = 0; i + 1 < c->npath; i++) len += v3_dist(c->px + 3 * i, c->px + 3 * i + 3);
  if (c->npath < 2 || len <= merge_tol) return 0; /* no travel: a stab does not cut */
  double t0 = now_ms();
  model_t *m = c->m;
  model_nodes_t nv = nodes(c), *ms = &nv;
  const size_t n = ms->n, nt = m->nsurf_tris;
  const uint32_t *tris = m->surf_tris;
  const double r = fmax(c->radius, c->p.min_radius_rel * c->h_mean);
  int rc = -1;
  uint8_t *node_in = malloc(n + 1), *tri_dead = malloc(nt + 1);
  uint32_t *map = malloc((n + 1) * sizeof *map), *nt_buf = NULL;
  ms_sweep_out_t sw = {0};
  nm_result_t nm = {0};
  if (!node_in || !tri_dead || !map) {
    verr_set(err, "cutting: out of memory");
    goto out;
  }
  /* Stage 1: swept-volume deletion. */
  ms_sweep_mark(n, ms->x, nt, tris, c->px, c->npath, r, c->ptri, c->npath, node_in, tri_dead);
  if (ms_sweep_cleanup(n, nt, tris, tri_dead, &sw, err)) goto out;
  if (sw.tris_dead == nt) {
    verr_set(err, "cutting: the cut would remove the whole surface (blade radius %g m); not applied", c->radius);
    goto out;
  }
  /* Stage 2: the incision curve through the path, current and rest. */
  double ctrl[4][3], ctrl_rest[4][3], w[4];
  bezier_fit_path(c->px, c->npath, NULL, w, ctrl);
  bezier_fit_path(c->pr, c->npath, w, NULL, ctrl_rest);
  /* Stage 3: node matching on the hole's boundary. */
  if (node_match(n, ms->x, sw.nhole, sw.hole, ctrl, merge_tol, &nm, err)) goto out;

  size_t keep = 0;
  for (size_t i = 0; i < n; i++) map[i] = sw.node_dead[i] ? UINT32_MAX : (uint32_t)keep++;
  const size_t nn = keep + nm.nnew;
  size_t ntris_new = nt - sw.tris_dead + nm.ntris;
  nt_buf = malloc((3 * ntris_new + 1) * sizeof *nt_buf);
  if (!nt_buf) {
    verr_set(err, "cutting: out of memory");
    goto out;
  }
  size_t q = 0;
  for (size_t t = 0; t < nt; t++)
    if (!tri_dead[t])
      for (int k = 0; k < 3; k++) nt_buf[q++] = map[tris[3 * t + k]];
  for (size_t k = 0; k < 3 * nm.ntris; k++) {
    uint32_t v = nm.tris[k];
    nt_buf[q++] = v < n ? map[v] : (uint32_t)(keep + (v - n));
  }
  if (c->edit->reserve(m, nn > n ? nn : n, c->p.eps_r > 0, err)) goto out;
  nv = nodes(c); /* the arrays may have moved */
  /* Residual stress (eq. 3-4, see ms_cut.h): the surviving ends of the cut
   * springs get eps_r K L0 along the rest direction away from the cut. */
  if (ms->f_res)
    for (size_t s = 0; s < sw.ncut; s++) {
      uint32_t u = sw.cut[2 * s], v = sw.cut[2 * s + 1];
      double d[3];
      v3_sub(d, ms->x_rest + 3 * (size_t)u, ms->x_rest + 3 * (size_t)v);
      double L0 = v3_normalize(d), F = c->p.eps_r * ms->edge_stiffness * L0;
      if (!sw.node_dead[u]) v3_axpy(ms->f_res + 3 * (size_t)u, d, F);
      if (!sw.node_dead[v]) v3_axpy(ms->f_res + 3 * (size_t)v, d, -F);
    }
  /* Compact the survivors in place (map[i] <= i), then append the curve nodes. */
  for (size_t i = 0; i < n; i++) {
    uint32_t j = map[i];
    if (j == UINT32_MAX || j == i) continue;
    memcpy(ms->x + 3 * (size_t)j, ms->x + 3 * i, 3 * sizeof(double));
    memcpy(ms->v + 3 * (size_t)j, ms->v + 3 * i, 3 * sizeof(double));
    memcpy(ms->x_rest + 3 * (size_t)j, ms->x_rest + 3 * i, 3 * sizeof(double));
    if (ms->f_res) memcpy(ms->f_res + 3 * (size_t)j, ms->f_res + 3 * i, 3 * sizeof(double));
    ms->mass[j] = ms->mass[i];
    ms->inv_mass[j] = ms->inv_mass[i];
  }
  for (size_t k = 0; k < nm.nnew; k++) {
    size_t j = keep + k;
    bezier_eval(ctrl, nm.a[k], ms->x + 3 * j);
    bezier_eval(ctrl_rest, nm.a[k], ms->x_rest + 3 * j);
    memset(ms->v + 3 * j, 0, 3 * sizeof(double));
    if (ms->f_res) memset(ms->f_res + 3 * j, 0, 3 * sizeof(double));
    ms->mass[j] = c->m0;
    ms->inv_mass[j] = 1 / c->m0;
  }
  memset(ms->f_ext, 0, 3 * nn * sizeof(double));
  model_topology_t topo = {.n = nn, .old_to_new = map, .old_n = n, .ntris = ntris_new, .tris = nt_buf};
  if (c->edit->commit(m, &topo, err)) {
    rc = -1; /* the topology did change: report, the caller passes it on */
    goto lips;
  }
  rc = 1;
lips:
  /* Lips: the old ones renumbered (deleted nodes dropped, emptied lips
   * removed), the new ones added. */
  size_t kept_lips = 0;
  for (size_t l = 0; l < c->nlips; l++) {
    lip_t *L = &c->lips[l];
    size_t o = 0;
    for (size_t i = 0; i < L->len; i++)
      if (map[L->nodes[i]] != UINT32_MAX) L->nodes[o++] = map[L->nodes[i]];
    L->len = o;
    if (o == 0)
      free(L->nodes);
    else
      c->lips[kept_lips++] = *L;
  }
  c->nlips = kept_lips;
  for (size_t l = 0; l < nm.nlips; l++) {
    nm_lip_t *L = &nm.lips[l];
    for (size_t i = 0; i < L->len; i++)
      L->nodes[i] = L->nodes[i] < n ? map[L->nodes[i]] : (uint32_t)(keep + (L->nodes[i] - n));
    if (lips_push(c, L->side, L->len, L->nodes) == 0) L->nodes = NULL; /* ownership moved */
  }
  c->st.segments++;
  c->st.nodes_deleted += sw.nodes_dead;
  c->st.nodes_added += nm.nnew;
  c->st.tris_deleted += sw.tris_dead;
  c->st.tris_added += nm.ntris;
  c->st.springs_cut += sw.ncut;
  c->st.holes_left_open += nm.open_left;
  c->st.last_segment_ms = now_ms() - t0;
out:
  free(node_in);
  free(tri_dead);
  free(map);
  free(nt_buf);
  ms_sweep_out_free(&sw);
  nm_result_free(&nm);
  return rc;
}

/* The triangles changed (here or elsewhere): crossed-triangle indices are stale. */
static void path_refresh(ms_cut_t *c) {
  if (c->m->topology_version == c->path_version) return;
  for (size_t i = 0; i < c->npath; i++) c->ptri[i] = UINT32_MAX;
  c->path_version = c->m->topology_version;
}

static int finish(ms_cut_t *c, verr_t *err) {
  path_refresh(c);
  int rc = c->active ? process_segment(c, err) : 0;
  c->active = 0;
  c->npath = 0;
  c->seg_len_acc = 0;
  return rc;
}

int ms_cut_step(ms_cut_t *c, const double p0[3], const double p1[3], double radius, verr_t *err) {
  if (!v3_isfinite(p0) || !v3_isfinite(p1) || !isfinite(radius))
    return verr_set(err, "cutting: blade pose or radius is not finite");
  if (!(radius > 0) || radius > c->p.max_radius)
    return verr_set(err, "cutting: blade radius %g m outside (0, %g]", radius, c->p.max_radius);
  path_refresh(c);
  /* A stability re-estimate left by the last topology change goes on, a few
   * power iterations per step (model.h edit->refine). */
  if (c->edit->refine && c->edit->refine(c->m, MS_CUT_REFINE_ITERATIONS, err) < 0) return -1;
  double x[3], xr[3];
  uint32_t tri = UINT32_MAX;
  int hit = find_crossing(c, p0, p1, radius, x, xr, &tri, err);
  if (hit < 0) return -1;
  if (!hit) return finish(c, err);
  c->st.steps_in_contact++;
  if (!c->active) {
    c->active = 1;
    c->st.cuts++;
    c->npath = 0;
    c->seg_len_acc = 0;
    c->radius = radius;
  }
  c->radius = fmax(c->radius, radius);
  if (c->npath > 0) {
    double d = v3_dist(x, c->px + 3 * (c->npath - 1));
    if (d < 1e-3 * c->h_mean) return 0; /* the blade has not moved along */
    c->seg_len_acc += d;
  }
  if (path_push(c, x, xr, tri, err)) return -1;
  if (c->seg_len_acc < c->p.segment_length) return 0;
  int rc = process_segment(c, err);
  /* The next segment starts where this one ended; its crossed triangle is gone. */
  v3_copy(c->px, c->px + 3 * (c->npath - 1));
  v3_copy(c->pr, c->pr + 3 * (c->npath - 1));
  c->ptri[0] = UINT32_MAX;
  c->npath = 1;
  c->seg_len_acc = 0;
  return rc;
}

int ms_cut_end(ms_cut_t *c, verr_t *err) { return finish(c, err); }

size_t ms_cut_incision_width(const ms_cut_t *c, double *mean, double *max) {
  const model_nodes_t nv = nodes(c);
  const double *X = nv.x;
  size_t count = 0;
  double sum = 0, mx = 0;
  for (size_t l = 0; l < c->nlips; l++) {
    const lip_t *A = &c->lips[l];
    if (A->side != 1) continue;
    for (size_t i = 0; i < A->len; i++) {
      const double *p = X + 3 * (size_t)A->nodes[i];
      /* A curve end shared by both sides is where the incision closes: no gap to measure. */
      int shared = 0;
      for (size_t k = 0; k < c->nlips && !shared; k++)
        for (size_t j = 0; j < c->lips[k].len && c->lips[k].side == 2 && !shared; j++)
          shared = c->lips[k].nodes[j] == A->nodes[i];
      if (shared) continue;
      double best = INFINITY;
      for (size_t k = 0; k < c->nlips; k++) {
        const lip_t *B = &c->lips[k];
        if (B->side != 2) continue;
        for (size_t j = 0; j + 1 < B->len; j++) {
          double d = ms_sweep_seg_seg_dist(p, p, X + 3 * (size_t)B->nodes[j], X + 3 * (size_t)B->nodes[j + 1]);
          if (d < best) best = d;
        }
      }
      if (!isfinite(best)) continue;
      sum += best;
      mx = fmax(mx, best);
      count++;
    }
  }
  if (mean) *mean = count ? sum / (double)count : 0;
  if (max) *max = mx;
  return count;
}

size_t ms_cut_lip_count(const ms_cut_t *c) { return c->nlips; }

const uint32_t *ms_cut_lip(const ms_cut_t *c, size_t k, int side, size_t *len) {
  if (k >= c->nlips || c->lips[k].side != side) {
    *len = 0;
    return NULL;
  }
  *len = c->lips[k].len;
  return c->lips[k].nodes;
}
