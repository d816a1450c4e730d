/* SPDX-License-Identifier: Apache-2.0 */
#include "physics/adaptive.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "vmath.h"
#include "vtime.h"

/* ---------------------------------------------------------------- hashing */

/* Midpoints and new springs are keyed by their unordered vertex pair. Open
 * addressing with linear probing; the table never holds more than its
 * allocated share, and clearing walks only the slots used since the last
 * clear, so a simplification costs the refined region, not the table. */
static uint64_t pair_key(uint32_t a, uint32_t b) { return a < b ? ((uint64_t)a << 32) | b : ((uint64_t)b << 32) | a; }

static size_t hash_slot(uint64_t k, size_t cap) {
  k ^= k >> 33;
  k *= 0xff51afd7ed558ccdULL;
  k ^= k >> 33;
  return (size_t)k & (cap - 1);
}

static int hash_init(ad_hash_t *h, size_t max_entries) {
  size_t cap = 16;
  while (cap < 2 * max_entries + 2) cap *= 2;
  h->cap = cap;
  h->key = malloc(cap * sizeof(uint64_t));
  h->val = malloc(cap * sizeof(uint32_t));
  h->used = malloc((max_entries + 1) * sizeof(uint32_t));
  h->nused = 0;
  if (!h->key || !h->val || !h->used) return -1;
  memset(h->key, 0xff, cap * sizeof(uint64_t));
  return 0;
}

static void hash_free(ad_hash_t *h) {
  free(h->key);
  free(h->val);
  free(h->used);
  memset(h, 0, sizeof *h);
}

static uint32_t hash_find(const ad_hash_t *h, uint32_t a, uint32_t b) {
  uint64_t k = pair_key(a, b);
  for (size_t s = hash_slot(k, h->cap);; s = (s + 1) & (h->cap - 1)) {
    if (h->key[s] == k) return h->val[s];
    if (h->key[s] == UINT64_MAX) return ADAPT_NONE;
  }
}

/* The caller has checked that the pair is absent. */
static void hash_put(ad_hash_t *h, uint32_t a, uint32_t b, uint32_t v) {
  uint64_t k = pair_key(a, b);
  size_t s = hash_slot(k, h->cap);
  while (h->key[s] != UINT64_MAX) s = (s + 1) & (h->cap - 1);
  h->key[s] = k;
  h->val[s] = v;
  h->used[h->nused++] = (uint32_t)s;
}

static void hash_clear(ad_hash_t *h) {
  for (size_t u = 0; u < h->nused; u++) h->key[h->used[u]] = UINT64_MAX;
  h->nused = 0;
}

/* Writes every page of a capacity array once at create, so the first
 * refinement does not take page faults in the physics thread. */
static void prefault(void *p, size_t bytes) {
  if (p) memset(p, 0, bytes);
}

/* --------------------------------------------------------------- geometry */

static double tri_area(const double *x, uint32_t a, uint32_t b, uint32_t c) {
  double e1[3], e2[3], n[3];
  v3_sub(e1, x + 3 * (size_t)b, x + 3 * (size_t)a);
  v3_sub(e2, x + 3 * (size_t)c, x + 3 * (size_t)a);
  v3_cross(n, e1, e2);
  return 0.5 * v3_norm(n);
}

typedef struct half_edge {
  uint64_t key;
  uint32_t face;
  uint32_t k;
} half_edge_t;

static int cmp_half_edge(const void *pa, const void *pb) {
  const half_edge_t *a = pa, *b = pb;
  if (a->key != b->key) return a->key < b->key ? -1 : 1;
  return (a->face > b->face) - (a->face < b->face);
}

/* ------------------------------------------------------------- stability */

/* y = M^-1 (A x) with A the rest-state spring matrix (per spring weight w_s
 * on u u^T) plus the home springs and diag_extra on the diagonal; fixed
 * nodes removed. `use_c` picks dashpots instead of springs. */
static void rest_matvec(const adaptive_t *ad, int use_c, double diag_extra, const double *x, double *y) {
  for (size_t i = 0; i < ad->n; i++) {
    double d = (use_c ? ad->ch[i] : ad->kh[i]) + diag_extra;
    for (int k = 0; k < 3; k++) y[3 * i + k] = d * x[3 * i + k];
  }
  for (size_t s = 0; s < ad->ns; s++) {
    if (s < ad->s0 && ad->spring_off[s]) continue;
    const ad_spring_t *sp = &ad->springs[s];
    double u[3], d[3];
    v3_sub(u, ad->x_rest + 3 * (size_t)sp->j, ad->x_rest + 3 * (size_t)sp->i);
    v3_normalize(u);
    v3_sub(d, x + 3 * (size_t)sp->i, x + 3 * (size_t)sp->j);
    double a = (use_c ? sp->c : sp->k) * v3_dot(u, d);
    v3_axpy(y + 3 * (size_t)sp->i, u, a);
    v3_axpy(y + 3 * (size_t)sp->j, u, -a);
  }
  for (size_t i = 0; i < ad->n; i++)
    for (int k = 0; k < 3; k++) y[3 * i + k] *= ad->inv_mass[i];
}

/* Largest eigenvalue of M^-1 A by power iteration (docs/numerics.md: omega_max
 * by power iteration), +2 % for the unconverged remainder. */
static double lambda_max(const adaptive_t *ad, int use_c, double diag_extra, double *x, double *y) {
  unsigned seed = 2024;
  size_t n3 = 3 * ad->n;
  for (size_t c = 0; c < n3; c++) {
    seed = seed * 1664525u + 1013904223u;
    x[c] = ((double)(seed >> 8) / 16777216.0 - 0.5) * (ad->inv_mass[c / 3] > 0);
  }
  double lambda = 0;
  for (int it = 0; it < 300; it++) {
    double nx = 0, ny = 0;
    for (size_t c = 0; c < n3; c++) nx += x[c] * x[c];
    if (!(nx > 0)) return 0;
    rest_matvec(ad, use_c, diag_extra, x, y);
    for (size_t c = 0; c < n3; c++) ny += y[c] * y[c];
    double next = sqrt(ny / nx);
    for (size_t c = 0; c < n3; c++) x[c] = y[c] / (ny > 0 ? sqrt(ny) : 1);
    if (it > 20 && fabs(next - lambda) <= 1e-4 * next) {
      lambda = next;
      break;
    }
    lambda = next;
  }
  return 1.02 * lambda;
}

/* Gershgorin row bounds of node i in M^-1 K and M^-1 C (block form: each
 * spring's 3x3 block has norm k): (2 sum_j k_ij + k_home + K_tool) / m_i and
 * (2 sum_j c_ij + c_home) / m_i. A true upper bound, unlike any estimate
 * calibrated on the coarse lattice: those fell 1-11 % short at levels 3-4
 * (level borders are stiffer than the lattice), while this one needs about
 * twice the sub-steps the power iteration would (measured on the spleen and
 * kidney, levels 1-4, 1x and 10x damping); multi-rate stepping keeps that
 * cost on the refined region only. */
static void node_bound(const adaptive_t *ad, size_t i, double *lk, double *lc) {
  double w = ad->inv_mass[i];
  double k = (2 * ad->ksum[i] + ad->kh[i] + ad->p.tool_stiffness) * w;
  double c = (2 * ad->csum[i] + ad->ch[i]) * w;
  if (k > *lk) *lk = k;
  if (c > *lc) *lc = c;
}

/* Largest h with h^2 l_k + 2 h l_c < 4: semi-implicit Euler on the extreme
 * modes of a damped system. */
static double damped_bound(double lk, double lc) {
  if (lk == 0 && lc == 0) return INFINITY;
  if (lk == 0) return 2.0 / lc;
  return (-lc + sqrt(lc * lc + 4 * lk)) / lk;
}

/* ----------------------------------------------------------------- create */

void adaptive_destroy(adaptive_t *ad) {
  void *ptrs[] = {
      ad->tris0,      ad->fadj0,     ad->fspr0,   ad->area0,      ad->varea0,     ad->vf_off,       ad->vf_idx,
      ad->x,          ad->v,         ad->x_rest,  ad->f,          ad->f_ext,      ad->ffine,        ad->forced,
      ad->mass,       ad->inv_mass,  ad->kh,      ad->ch,         ad->fixed,      ad->vlevel,       ad->anchor,
      ad->tris,       ad->tri_face,  ad->springs, ad->spring_off, ad->root_face,  ad->root_node,    ad->root_first,
      ad->root_count, ad->face_root, ad->nodes,   ad->disabled,   ad->modv,       ad->vflag,        ad->stamp,
      ad->ksum,       ad->csum,      ad->vmark,   ad->fine,       ad->fine_nodes, ad->fine_springs, ad->is_forced,
      ad->im_fine,
  };
  for (size_t k = 0; k < sizeof ptrs / sizeof ptrs[0]; k++) free(ptrs[k]);
  model_guard_free(&ad->guard);
  hash_free(&ad->mid);
  hash_free(&ad->edge);
  memset(ad, 0, sizeof *ad);
}

/* Coarse edges: springs and face adjacency from sorted half-edges. An edge
 * with three or more faces is refused: splitting it could not be made
 * conforming from two sides. */
static int build_edges(adaptive_t *ad, verr_t *err) {
  size_t nh = 3 * ad->t0;
  half_edge_t *he = malloc((nh + 1) * sizeof *he);
  if (!he) return verr_set(err, "adaptive: out of memory for edges");
  for (size_t t = 0; t < ad->t0; t++)
    for (uint32_t k = 0; k < 3; k++) {
      uint32_t a = ad->tris0[3 * t + k], b = ad->tris0[3 * t + (k + 1) % 3];
      if (a == b) {
        free(he);
        return verr_set(err, "adaptive: triangle %zu repeats vertex %u", t, a);
      }
      he[3 * t + k] = (half_edge_t){pair_key(a, b), (uint32_t)t, k};
    }
  qsort(he, nh, sizeof *he, cmp_half_edge);
  size_t ne = 0;
  for (size_t e = 0; e < nh;) {
    size_t e2 = e;
    while (e2 < nh && he[e2].key == he[e].key) e2++;
    if (e2 - e > 2) {
      uint64_t k = he[e].key;
      free(he);
      return verr_set(err, "adaptive: edge (%u, %u) has %zu triangles; the surface must be edge-manifold",
                      (unsigned)(k >> 32), (unsigned)(k & 0xffffffffu), e2 - e);
    }
    for (size_t q = e; q < e2; q++) {
      ad->fspr0[3 * he[q].face + he[q].k] = (uint32_t)ne;
      ad->fadj0[3 * he[q].face + he[q].k] = e2 - e == 2 ? he[q == e ? e + 1 : e].face : ADAPT_NONE;
    }
    ad_spring_t *sp = &ad->springs[ne++];
    sp->i = (uint32_t)(he[e].key >> 32);
    sp->j = (uint32_t)(he[e].key & 0xffffffffu);
    sp->rest = v3_dist(ad->x_rest + 3 * (size_t)sp->i, ad->x_rest + 3 * (size_t)sp->j);
    sp->k = ad->p.stiffness;
    sp->c = ad->p.damping;
    e = e2;
  }
  ad->s0 = ne;
  free(he);
  return 0;
}

/* The deepest refinement roots at most the faces within refine_levels + 1
 * edge-hops of the touched node's one-ring faces: 2:1 balance forces level
 * l - 1 next to level l, one hop per level, and green closure one hop more.
 * Capacity is the largest such neighbourhood over all vertices. */
static size_t max_neighbourhood(const adaptive_t *ad, int depth) {
  uint32_t *stampf = malloc((ad->t0 + 1) * sizeof(uint32_t));
  uint32_t *queue = malloc((ad->t0 + 1) * sizeof(uint32_t));
  uint8_t *dep = malloc(ad->t0 + 1);
  if (!stampf || !queue || !dep) {
    free(stampf);
    free(queue);
    free(dep);
    return 0;
  }
  for (size_t f = 0; f < ad->t0; f++) stampf[f] = ADAPT_NONE;
  size_t best = 0;
  for (size_t t = 0; t < ad->n0; t++) {
    size_t qh = 0, qt = 0;
    for (uint32_t a = ad->vf_off[t]; a < ad->vf_off[t + 1]; a++) {
      uint32_t f = ad->vf_idx[a];
      if (stampf[f] == t) continue;
      stampf[f] = (uint32_t)t;
      dep[f] = 0;
      queue[qt++] = f;
    }
    while (qh < qt) {
      uint32_t f = queue[qh++];
      if (dep[f] >= depth) continue;
      for (int k = 0; k < 3; k++) {
        uint32_t g = ad->fadj0[3 * (size_t)f + k];
        if (g == ADAPT_NONE || stampf[g] == t) continue;
        stampf[g] = (uint32_t)t;
        dep[g] = (uint8_t)(dep[f] + 1);
        queue[qt++] = g;
      }
    }
    if (qt > best) best = qt;
  }
  free(stampf);
  free(queue);
  free(dep);
  return best;
}

int adaptive_create(adaptive_t *ad, const mesh_t *s, const adaptive_params_t *p, double dt, int substeps, verr_t *err) {
  memset(ad, 0, sizeof *ad);
  if (!(p->mass > 0) || !isfinite(p->mass) || !(p->stiffness >= 0) || !(p->damping >= 0) || !(p->home_stiffness >= 0) ||
      !(p->home_damping >= 0) || !isfinite(p->stiffness + p->damping + p->home_stiffness + p->home_damping) ||
      !v3_isfinite(p->gravity) || !(p->tool_stiffness >= 0))
    return verr_set(err, "adaptive: mass must be > 0, stiffness, damping and home springs >= 0");
  if (p->refine_levels < 0 || p->refine_levels > ADAPT_MAX_LEVELS)
    return verr_set(err, "adaptive: refine_levels must be 0..%d (got %d)", ADAPT_MAX_LEVELS, p->refine_levels);
  if (p->refine_levels > 0 && !(p->refine_area > 0 && isfinite(p->refine_area)))
    return verr_set(err, "adaptive: refine_area must be > 0 (got %g)", p->refine_area);
  if (!(p->refine_force >= 0) || !(p->release_time >= 0) || !(dt > 0))
    return verr_set(err, "adaptive: refine_force, release_time must be >= 0 and dt > 0");
  if (s->ntris == 0 || s->nverts >= UINT32_MAX / 2 || s->ntris >= UINT32_MAX / 2)
    return verr_set(err, "adaptive: mesh has no triangles or is too large");
  if (mesh_validate(s, "adaptive surface", err)) return -1;
  ad->p = *p;
  ad->dt = dt;
  size_t n0 = ad->n0 = s->nverts, t0 = ad->t0 = s->ntris;
  int L = p->refine_levels;

  ad->tris0 = malloc(3 * t0 * sizeof(uint32_t));
  ad->fadj0 = malloc(3 * t0 * sizeof(uint32_t));
  ad->fspr0 = malloc(3 * t0 * sizeof(uint32_t));
  ad->area0 = malloc(t0 * sizeof(double));
  ad->varea0 = calloc(n0, sizeof(double));
  ad->vf_off = calloc(n0 + 1, sizeof(uint32_t));
  ad->vf_idx = malloc(3 * t0 * sizeof(uint32_t));
  ad->x_rest = malloc(3 * n0 * sizeof(double)); /* coarse only for now; regrown below */
  ad->springs = malloc(3 * t0 * sizeof(ad_spring_t));
  if (!ad->tris0 || !ad->fadj0 || !ad->fspr0 || !ad->area0 || !ad->varea0 || !ad->vf_off || !ad->vf_idx ||
      !ad->x_rest || !ad->springs) {
    adaptive_destroy(ad);
    return verr_set(err, "adaptive: out of memory for %zu triangles", t0);
  }
  memcpy(ad->tris0, s->tris, 3 * t0 * sizeof(uint32_t));
  memcpy(ad->x_rest, s->pos, 3 * n0 * sizeof(double));
  if (build_edges(ad, err)) {
    adaptive_destroy(ad);
    return -1;
  }
  for (size_t t = 0; t < t0; t++) {
    const uint32_t *f = ad->tris0 + 3 * t;
    ad->area0[t] = tri_area(ad->x_rest, f[0], f[1], f[2]);
    for (int k = 0; k < 3; k++) {
      ad->varea0[f[k]] += ad->area0[t];
      ad->vf_off[f[k] + 1]++;
    }
  }
  for (size_t i = 0; i < n0; i++) ad->vf_off[i + 1] += ad->vf_off[i];
  {
    uint32_t *fill = calloc(n0 + 1, sizeof(uint32_t));
    if (!fill) {
      adaptive_destroy(ad);
      return verr_set(err, "adaptive: out of memory");
    }
    for (size_t t = 0; t < t0; t++)
      for (int k = 0; k < 3; k++) {
        uint32_t i = ad->tris0[3 * t + k];
        ad->vf_idx[ad->vf_off[i] + fill[i]++] = (uint32_t)t;
      }
    free(fill);
  }
  for (size_t t = 0; t < t0; t++)
    if (!(ad->area0[t] > 0)) {
      size_t nt = t;
      adaptive_destroy(ad);
      return verr_set(err, "adaptive: triangle %zu has zero area (its mass share would be undefined)", nt);
    }

  /* Capacity. Per root face at most 4^L leaves, each closed by at most as
   * many triangles as its red split, (4^(L+1) - 1) / 3 tree nodes, 4^L - 1
   * new vertices (3 midpoints per split, 4^L - 1)/3 splits) and three
   * springs per triangle. */
  size_t pow4 = (size_t)1 << (2 * L);
  size_t roots = max_neighbourhood(ad, L + 1);
  if (roots == 0) {
    adaptive_destroy(ad);
    return verr_set(err, "adaptive: out of memory");
  }
  if (roots > t0) roots = t0;
  ad->cap_roots = roots;
  ad->cap_t = t0 + roots * (pow4 - 1);
  ad->cap_v = n0 + roots * (pow4 - 1);
  ad->cap_s = ad->s0 + 3 * roots * pow4;
  ad->cap_nodes = roots * ((4 * pow4 - 1) / 3);
  if (ad->cap_t >= UINT32_MAX / 4 || ad->cap_v >= UINT32_MAX / 4 || ad->cap_s >= UINT32_MAX / 4) {
    adaptive_destroy(ad);
    return verr_set(err, "adaptive: refine_levels %d needs too much capacity on this mesh", L);
  }
  size_t cv = ad->cap_v;
  double *xr = realloc(ad->x_rest, 3 * cv * sizeof(double));
  ad_spring_t *sp = realloc(ad->springs, ad->cap_s * sizeof(ad_spring_t));
  if (xr) ad->x_rest = xr;
  if (sp) ad->springs = sp;
  ad->x = calloc(3 * cv, sizeof(double));
  ad->v = calloc(3 * cv, sizeof(double));
  ad->f = calloc(3 * cv, sizeof(double));
  ad->f_ext = calloc(3 * cv, sizeof(double));
  int guard_rc = model_guard_reserve(&ad->guard, cv);
  ad->mass = calloc(cv, sizeof(double));
  ad->inv_mass = calloc(cv, sizeof(double));
  ad->kh = calloc(cv, sizeof(double));
  ad->ch = calloc(cv, sizeof(double));
  ad->fixed = calloc(cv, 1);
  ad->vlevel = calloc(cv, 1);
  ad->anchor = calloc(cv - n0 + 1, sizeof(uint32_t));
  ad->tris = malloc(3 * ad->cap_t * sizeof(uint32_t));
  ad->tri_face = malloc(ad->cap_t * sizeof(uint32_t));
  ad->spring_off = calloc(ad->s0 + 1, 1);
  ad->root_face = malloc(roots * sizeof(uint32_t));
  ad->root_node = malloc(roots * sizeof(uint32_t));
  ad->root_first = malloc(roots * sizeof(uint32_t));
  ad->root_count = malloc(roots * sizeof(uint32_t));
  ad->face_root = malloc(t0 * sizeof(uint32_t));
  ad->nodes = malloc(ad->cap_nodes * sizeof(ad_node_t));
  ad->disabled = malloc((ad->s0 + 1) * sizeof(uint32_t));
  ad->modv = malloc((n0 + 1) * sizeof(uint32_t));
  ad->vflag = calloc(n0, 1);
  ad->stamp = calloc(ad->cap_s, sizeof(uint32_t));
  ad->ksum = calloc(cv, sizeof(double));
  ad->csum = calloc(cv, sizeof(double));
  ad->vmark = calloc(cv, 1);
  ad->fine = calloc(cv, 1);
  ad->fine_nodes = calloc(cv, sizeof(uint32_t));
  ad->fine_springs = calloc(ad->cap_s, sizeof(uint32_t));
  ad->ffine = calloc(3 * cv, sizeof(double));
  ad->forced = calloc(cv, sizeof(uint32_t));
  ad->is_forced = calloc(cv, 1);
  ad->im_fine = calloc(cv, sizeof(double));
  if (!ad->im_fine || !ad->vmark || !ad->fine || !ad->fine_nodes || !ad->fine_springs || !ad->ffine || !ad->forced ||
      !ad->is_forced || !xr || !sp || !ad->x || !ad->v || !ad->f || !ad->f_ext || guard_rc || !ad->mass ||
      !ad->inv_mass || !ad->kh || !ad->ch || !ad->fixed || !ad->vlevel || !ad->anchor || !ad->tris || !ad->tri_face ||
      !ad->spring_off || !ad->root_face || !ad->root_node || !ad->root_first || !ad->root_count || !ad->face_root ||
      !ad->nodes || !ad->disabled || !ad->modv || !ad->vflag || !ad->stamp || !ad->ksum || !ad->csum ||
      hash_init(&ad->mid, cv - n0) || hash_init(&ad->edge, ad->cap_s - ad->s0)) {
    adaptive_destroy(ad);
    return verr_set(err, "adaptive: out of memory for the refinement capacity (%zu vertices)", cv);
  }

  prefault(ad->x_rest + 3 * n0, 3 * (cv - n0) * sizeof(double));
  prefault(ad->springs + ad->s0, (ad->cap_s - ad->s0) * sizeof(ad_spring_t));
  prefault(ad->tris, 3 * ad->cap_t * sizeof(uint32_t));
  prefault(ad->tri_face, ad->cap_t * sizeof(uint32_t));
  prefault(ad->nodes, ad->cap_nodes * sizeof(ad_node_t));
  prefault(ad->root_face, roots * sizeof(uint32_t));
  prefault(ad->root_node, roots * sizeof(uint32_t));
  prefault(ad->root_first, roots * sizeof(uint32_t));
  prefault(ad->root_count, roots * sizeof(uint32_t));
  prefault(ad->disabled, (ad->s0 + 1) * sizeof(uint32_t));
  prefault(ad->modv, (n0 + 1) * sizeof(uint32_t));
  prefault(ad->mid.val, ad->mid.cap * sizeof(uint32_t));
  prefault(ad->mid.used, (cv - n0 + 1) * sizeof(uint32_t));
  prefault(ad->edge.val, ad->edge.cap * sizeof(uint32_t));
  prefault(ad->edge.used, (ad->cap_s - ad->s0 + 1) * sizeof(uint32_t));
  {
    double *dz[] = {ad->x, ad->v, ad->f, ad->f_ext, ad->guard.x, ad->guard.v, ad->ffine};
    for (size_t k = 0; k < sizeof dz / sizeof dz[0]; k++) prefault(dz[k], 3 * cv * sizeof(double));
    double *dn[] = {ad->mass, ad->inv_mass, ad->kh, ad->ch, ad->ksum, ad->csum, ad->im_fine};
    for (size_t k = 0; k < sizeof dn / sizeof dn[0]; k++) prefault(dn[k], cv * sizeof(double));
    prefault(ad->fixed, cv);
    prefault(ad->vlevel, cv);
    prefault(ad->vmark, cv);
    prefault(ad->fine, cv);
    prefault(ad->is_forced, cv);
    prefault(ad->anchor, (cv - n0 + 1) * sizeof(uint32_t));
    prefault(ad->fine_nodes, cv * sizeof(uint32_t));
    prefault(ad->forced, cv * sizeof(uint32_t));
    prefault(ad->fine_springs, ad->cap_s * sizeof(uint32_t));
    prefault(ad->stamp, ad->cap_s * sizeof(uint32_t));
  }

  /* Coarse state: equal lumped masses as in the thesis' eq. 5.10 setting
   * (and as mass_spring does: area weighting would give the small triangles
   * of real meshes small masses and a much smaller stable step). */
  ad->n = n0;
  ad->nt = t0;
  ad->ns = ad->s0;
  ad->m0 = p->mass / (double)n0;
  memcpy(ad->x, s->pos, 3 * n0 * sizeof(double));
  memcpy(ad->tris, ad->tris0, 3 * t0 * sizeof(uint32_t));
  for (size_t t = 0; t < t0; t++) {
    ad->tri_face[t] = (uint32_t)t;
    ad->face_root[t] = ADAPT_NONE;
  }
  for (size_t i = 0; i < n0; i++) {
    ad->mass[i] = ad->m0;
    ad->inv_mass[i] = 1.0 / ad->m0;
    ad->kh[i] = p->home_stiffness;
    ad->ch[i] = p->home_damping;
  }

  /* Coarse sub-steps from the semi-implicit Euler bound of the extreme
   * modes, h^2 l_k + 2 h l_c < 4, with the tool spring acting like an extra
   * home spring (it acts on the contact vertices). */
  double lk = lambda_max(ad, 0, p->tool_stiffness, ad->guard.x, ad->guard.v);
  double lc = lambda_max(ad, 1, 0, ad->guard.x, ad->guard.v);
  memset(ad->guard.x, 0, 3 * n0 * sizeof(double));
  memset(ad->guard.v, 0, 3 * n0 * sizeof(double));
  ad->stable_dt0 = damped_bound(lk, lc);
  if (substeps > 0) {
    ad->substeps0 = substeps;
  } else {
    double safe = 0.9 * ad->stable_dt0, need = isfinite(safe) ? ceil(dt / safe) : 1;
    if (!(need <= 256)) {
      double sdt = ad->stable_dt0;
      adaptive_destroy(ad);
      return verr_set(err,
                      "adaptive: stable only below dt = %.3g s, %.0f sub-steps of the %.3g s step (limit 256); "
                      "lower stiffness, damping or tool stiffness, or raise the mass",
                      sdt, need, dt);
    }
    ad->substeps0 = need < 1 ? 1 : (int)need;
  }
  ad->substeps = ad->substeps0;
  ad->fine_ratio = 1;
  ad->step_touched = ADAPT_NONE;
  ad->centre = ADAPT_NONE;
  return 0;
}

size_t adaptive_fix_below(adaptive_t *ad, double z) {
  size_t count = 0;
  for (size_t i = 0; i < ad->n0; i++)
    if (ad->x_rest[3 * i + 2] < z) {
      ad->fixed[i] = 1;
      ad->inv_mass[i] = 0;
      count++;
    }
  return count;
}

/* ------------------------------------------------------------- refinement */

static uint32_t add_root(adaptive_t *ad, uint32_t f) {
  if (ad->face_root[f] != ADAPT_NONE) return ad->face_root[f];
  if (ad->nroots >= ad->cap_roots || ad->nnodes >= ad->cap_nodes) {
    ad->failed = 1;
    return ADAPT_NONE;
  }
  uint32_t r = (uint32_t)ad->nroots++, ni = (uint32_t)ad->nnodes++;
  ad_node_t *nd = &ad->nodes[ni];
  memcpy(nd->v, ad->tris0 + 3 * (size_t)f, 3 * sizeof(uint32_t));
  nd->cedge[0] = 0;
  nd->cedge[1] = 1;
  nd->cedge[2] = 2;
  nd->level = 0;
  nd->root = r;
  nd->child = ADAPT_NONE;
  ad->root_face[r] = f;
  ad->root_node[r] = ni;
  ad->face_root[f] = r;
  for (int k = 0; k < 3; k++) {
    uint32_t i = nd->v[k];
    if (!(ad->vflag[i] & 1)) {
      ad->vflag[i] |= 1;
      ad->modv[ad->nmodv++] = i;
    }
  }
  return r;
}

/* The midpoint of (a, b), created on first use: on the segment at rest and
 * in the current state (the refined surface is the coarse surface), with the
 * mean velocity. Its mass is assigned by identify(). */
static uint32_t midpoint(adaptive_t *ad, uint32_t a, uint32_t b, int level) {
  uint32_t m = hash_find(&ad->mid, a, b);
  if (m != ADAPT_NONE) return m;
  if (ad->n >= ad->cap_v) {
    ad->failed = 1;
    return ADAPT_NONE;
  }
  m = (uint32_t)ad->n++;
  for (int k = 0; k < 3; k++) {
    size_t ia = 3 * (size_t)a + k, ib = 3 * (size_t)b + k, im = 3 * (size_t)m + k;
    ad->x_rest[im] = 0.5 * (ad->x_rest[ia] + ad->x_rest[ib]);
    ad->x[im] = 0.5 * (ad->x[ia] + ad->x[ib]);
    ad->v[im] = 0.5 * (ad->v[ia] + ad->v[ib]);
    ad->f_ext[im] = 0;
  }
  ad->fixed[m] = ad->fixed[a] && ad->fixed[b];
  ad->vlevel[m] = (uint8_t)level;
  ad->anchor[m - ad->n0] = a < ad->n0 ? a : ad->anchor[a - ad->n0];
  ad->mass[m] = 0;
  hash_put(&ad->mid, a, b, m);
  return m;
}

/* Red split of a leaf into four (docs/methods.md B §5.2.2.3: "subdivide it into four
 * triangles"), children in the parent's orientation. Splitting an edge that
 * lies on the root face's boundary roots the coarse face across it, so the
 * closure below sees it. */
static void red(adaptive_t *ad, uint32_t ni) {
  if (ad->nnodes + 4 > ad->cap_nodes) {
    ad->failed = 1;
    return;
  }
  ad_node_t nd = ad->nodes[ni];
  int lv = nd.level + 1;
  uint32_t a = nd.v[0], b = nd.v[1], c = nd.v[2];
  uint32_t mab = midpoint(ad, a, b, lv), mbc = midpoint(ad, b, c, lv), mca = midpoint(ad, c, a, lv);
  if (ad->failed) return;
  uint32_t first = (uint32_t)ad->nnodes;
  ad->nnodes += 4;
  const uint32_t cv[4][3] = {{a, mab, mca}, {mab, b, mbc}, {mca, mbc, c}, {mab, mbc, mca}};
  const int8_t ce[4][3] = {
      {nd.cedge[0], -1, nd.cedge[2]}, {nd.cedge[0], nd.cedge[1], -1}, {-1, nd.cedge[1], nd.cedge[2]}, {-1, -1, -1}};
  for (int q = 0; q < 4; q++) {
    ad_node_t *ch = &ad->nodes[first + q];
    memcpy(ch->v, cv[q], sizeof ch->v);
    memcpy(ch->cedge, ce[q], sizeof ch->cedge);
    ch->level = (uint8_t)lv;
    ch->root = nd.root;
    ch->child = ADAPT_NONE;
  }
  ad->nodes[ni].child = first;
  if (lv > ad->max_level) ad->max_level = lv;
  uint32_t f = ad->root_face[nd.root];
  for (int k = 0; k < 3; k++) {
    if (nd.cedge[k] < 0) continue;
    uint32_t g = ad->fadj0[3 * (size_t)f + (size_t)nd.cedge[k]];
    if (g != ADAPT_NONE) add_root(ad, g);
  }
}

/* The thesis' marking: a face above the threshold area is split, then each
 * child again while above it, up to refine_levels. */
static void mark(adaptive_t *ad, uint32_t ni) {
  if (ad->failed) return;
  const ad_node_t *nd = &ad->nodes[ni];
  if (nd->level >= ad->p.refine_levels) return;
  if (!(tri_area(ad->x_rest, nd->v[0], nd->v[1], nd->v[2]) > ad->p.refine_area)) return;
  red(ad, ni);
  if (ad->failed) return;
  uint32_t c = ad->nodes[ni].child;
  for (uint32_t q = 0; q < 4; q++) mark(ad, c + q);
}

/* A leaf whose neighbour is two or more levels finer along an edge: that
 * edge carries more than one hanging vertex, which no green template
 * closes, so the leaf must be split (2:1 balance). */
static int unbalanced(const adaptive_t *ad, const ad_node_t *nd) {
  for (int k = 0; k < 3; k++) {
    uint32_t a = nd->v[k], b = nd->v[(k + 1) % 3];
    uint32_t m = hash_find(&ad->mid, a, b);
    if (m != ADAPT_NONE && (hash_find(&ad->mid, a, m) != ADAPT_NONE || hash_find(&ad->mid, m, b) != ADAPT_NONE))
      return 1;
  }
  return 0;
}

#define LEAF_STACK (4 * ADAPT_MAX_LEVELS + 8)

static void balance(adaptive_t *ad) {
  int changed = 1;
  while (changed && !ad->failed) {
    changed = 0;
    for (size_t r = 0; r < ad->nroots && !ad->failed; r++) { /* nroots may grow */
      uint32_t stack[LEAF_STACK];
      int sp = 0;
      stack[sp++] = ad->root_node[r];
      while (sp > 0 && !ad->failed) {
        uint32_t ni = stack[--sp];
        const ad_node_t *nd = &ad->nodes[ni];
        if (nd->child != ADAPT_NONE) {
          for (uint32_t q = 0; q < 4; q++) stack[sp++] = nd->child + q;
          continue;
        }
        if (!unbalanced(ad, nd)) continue;
        /* Cannot happen below refine_levels (the finest leaves have no finer
         * neighbour); treated as a failure rather than a T-junction. */
        if (nd->level >= ad->p.refine_levels) {
          ad->failed = 1;
          break;
        }
        red(ad, ni);
        changed = 1;
      }
    }
  }
}

static void put_tri(adaptive_t *ad, uint32_t f, int *first, uint32_t a, uint32_t b, uint32_t c) {
  uint32_t slot;
  if (*first) {
    slot = f; /* the coarse face's own slot keeps its first piece */
    *first = 0;
  } else {
    if (ad->nt >= ad->cap_t) {
      ad->failed = 1;
      return;
    }
    slot = (uint32_t)ad->nt++;
  }
  ad->tris[3 * (size_t)slot] = a;
  ad->tris[3 * (size_t)slot + 1] = b;
  ad->tris[3 * (size_t)slot + 2] = c;
  ad->tri_face[slot] = f;
}

/* Leaves to triangles: green templates close the hanging midpoints. */
static void emit(adaptive_t *ad) {
  for (size_t r = 0; r < ad->nroots && !ad->failed; r++) {
    uint32_t f = ad->root_face[r];
    int first = 1;
    ad->root_first[r] = (uint32_t)ad->nt;
    uint32_t stack[LEAF_STACK];
    int sp = 0;
    stack[sp++] = ad->root_node[r];
    while (sp > 0 && !ad->failed) {
      const ad_node_t *nd = &ad->nodes[stack[--sp]];
      if (nd->child != ADAPT_NONE) {
        for (uint32_t q = 0; q < 4; q++) stack[sp++] = nd->child + q;
        continue;
      }
      const uint32_t *v = nd->v;
      uint32_t m[3];
      int h = 0;
      for (int k = 0; k < 3; k++) {
        m[k] = hash_find(&ad->mid, v[k], v[(k + 1) % 3]);
        h += m[k] != ADAPT_NONE;
      }
      if (h == 0) {
        put_tri(ad, f, &first, v[0], v[1], v[2]);
      } else if (h == 3) {
        put_tri(ad, f, &first, v[0], m[0], m[2]);
        put_tri(ad, f, &first, m[0], v[1], m[1]);
        put_tri(ad, f, &first, m[2], m[1], v[2]);
        put_tri(ad, f, &first, m[0], m[1], m[2]);
      } else if (h == 1) {
        int s = m[0] != ADAPT_NONE ? 0 : m[1] != ADAPT_NONE ? 1 : 2;
        uint32_t a = v[s], b = v[(s + 1) % 3], c = v[(s + 2) % 3];
        put_tri(ad, f, &first, a, m[s], c);
        put_tri(ad, f, &first, m[s], b, c);
      } else {
        /* Edges a-b and b-c split, c-a not: the corner at b, and the quad
         * (a, mab, mbc, c) cut along its shorter diagonal at rest. */
        int u = m[0] == ADAPT_NONE ? 0 : m[1] == ADAPT_NONE ? 1 : 2;
        uint32_t c = v[u], a = v[(u + 1) % 3], b = v[(u + 2) % 3];
        uint32_t mab = m[(u + 1) % 3], mbc = m[(u + 2) % 3];
        put_tri(ad, f, &first, mab, b, mbc);
        double d1 = v3_dist(ad->x_rest + 3 * (size_t)a, ad->x_rest + 3 * (size_t)mbc);
        double d2 = v3_dist(ad->x_rest + 3 * (size_t)mab, ad->x_rest + 3 * (size_t)c);
        if (d1 <= d2) {
          put_tri(ad, f, &first, a, mab, mbc);
          put_tri(ad, f, &first, a, mbc, c);
        } else {
          put_tri(ad, f, &first, a, mab, c);
          put_tri(ad, f, &first, mab, mbc, c);
        }
      }
    }
    ad->root_count[r] = (uint32_t)(ad->nt - ad->root_first[r]);
  }
}

/* Triangles of root r: its coarse slot, then the appended run. */
#define FOR_ROOT_TRIS(ad, r, tv)                                                                                       \
  for (size_t tv##_q = 0, tv = (ad)->root_face[r]; tv##_q <= (ad)->root_count[r];                                      \
       tv = (ad)->root_first[r] + tv##_q, tv##_q++)

/* Springs: coarse edges that were split are switched off (their halves
 * replace them); every edge with a new vertex becomes a new spring. */
static void build_springs(adaptive_t *ad) {
  for (size_t r = 0; r < ad->nroots; r++) {
    uint32_t f = ad->root_face[r];
    for (int k = 0; k < 3; k++) {
      uint32_t a = ad->tris0[3 * (size_t)f + k], b = ad->tris0[3 * (size_t)f + (k + 1) % 3];
      uint32_t s = ad->fspr0[3 * (size_t)f + k];
      if (hash_find(&ad->mid, a, b) != ADAPT_NONE && !ad->spring_off[s]) {
        ad->spring_off[s] = 1;
        ad->disabled[ad->ndisabled++] = s;
      }
    }
  }
  for (size_t r = 0; r < ad->nroots && !ad->failed; r++) {
    FOR_ROOT_TRIS(ad, r, t) {
      const uint32_t *tri = ad->tris + 3 * t;
      for (int k = 0; k < 3; k++) {
        uint32_t a = tri[k], b = tri[(k + 1) % 3];
        if (a < ad->n0 && b < ad->n0) continue; /* an unsplit coarse edge: its spring stays */
        if (hash_find(&ad->edge, a, b) != ADAPT_NONE) continue;
        if (ad->ns >= ad->cap_s) {
          ad->failed = 1;
          return;
        }
        uint32_t s = (uint32_t)ad->ns++;
        ad->springs[s] = (ad_spring_t){a, b, v3_dist(ad->x_rest + 3 * (size_t)a, ad->x_rest + 3 * (size_t)b), 0, 0};
        hash_put(&ad->edge, a, b, s);
      }
    }
  }
}

/* ADAPT_HOME_MATCH. The force to press a surface model in is carried by its
 * home springs (a membrane's edge springs have no first-order stiffness
 * across it): pushing the touched node's one-ring in rigidly by d costs
 * about the sum of the home stiffnesses on it, times d. The coarse model
 * lumps each ring vertex's whole surrounding area there, its outer faces
 * included; refined, part of that area sits on free new vertices and the
 * same push needs 15-20 % less force. This rule scales the home springs on
 * the one-ring faces so their sum is the coarse one-ring's. It is not the
 * default: that push is itself a coarse-mesh artefact, and a probe whose
 * force is spread over a fixed radius (as the server's contact patch is)
 * then feels ~20 % stiffer, while by-mass home springs keep it within 3 %.
 * Mass is not touched. */
static void match_home(adaptive_t *ad) {
  double coarse = 0, refined = 0;
  uint32_t c = ad->centre;
  for (uint32_t a = ad->vf_off[c]; a < ad->vf_off[c + 1]; a++) {
    uint32_t f = ad->vf_idx[a], r = ad->face_root[f];
    for (int k = 0; k < 3; k++) {
      uint32_t i = ad->tris0[3 * (size_t)f + k];
      if (!(ad->vmark[i] & 2)) {
        ad->vmark[i] |= 2;
        coarse += ad->p.home_stiffness;
      }
    }
    FOR_ROOT_TRIS(ad, r, t) {
      for (int k = 0; k < 3; k++) {
        uint32_t i = ad->tris[3 * t + k];
        if (!(ad->vmark[i] & 1)) {
          ad->vmark[i] |= 1;
          refined += ad->kh[i];
        }
      }
    }
  }
  double s = refined > 0 && coarse > 0 ? coarse / refined : 1;
  ad->home_match = s;
  for (uint32_t a = ad->vf_off[c]; a < ad->vf_off[c + 1]; a++) {
    uint32_t f = ad->vf_idx[a], r = ad->face_root[f];
    for (int k = 0; k < 3; k++) ad->vmark[ad->tris0[3 * (size_t)f + k]] &= (uint8_t)~2u;
    FOR_ROOT_TRIS(ad, r, t) {
      for (int k = 0; k < 3; k++) {
        uint32_t i = ad->tris[3 * t + k];
        if (ad->vmark[i] & 1) {
          ad->vmark[i] = 0;
          ad->kh[i] *= s;
          ad->ch[i] *= s;
        }
      }
    }
  }
}

/* Parameter identification (docs/methods.md B §5.2.3). */
static void identify(adaptive_t *ad) {
  const adaptive_params_t *p = &ad->p;
  size_t n0 = ad->n0;
  if (p->mass_rule == ADAPT_MASS_UNIFORM) {
    /* Eq. 5.10-5.11 with N old and N' new nodes: old masses x N / N', new
     * ones the mean of their parents x N / N'. From equal coarse masses both
     * give M / N' for every node. */
    double m = p->mass / (double)ad->n;
    for (size_t i = 0; i < ad->n; i++) ad->mass[i] = m;
  } else {
    /* Each refined coarse face f carries the parts of its vertices' masses
     * that lie over it, m_i A_f / A_i (A_i: the area around vertex i); it
     * gives them back to its new triangles by area, a third to each corner.
     * Mass is conserved face by face (eq. 5.10-5.11's requirement) and
     * stays where it was; a node bordering several levels gets the
     * area-weighted blend that eq. 5.12-5.14 approximate with edge counts. */
    for (size_t r = 0; r < ad->nroots; r++) {
      uint32_t f = ad->root_face[r];
      double mu = 0, area = 0;
      for (int k = 0; k < 3; k++) {
        uint32_t i = ad->tris0[3 * (size_t)f + k];
        double share = ad->m0 * ad->area0[f] / ad->varea0[i];
        mu += share;
        ad->mass[i] -= share;
      }
      FOR_ROOT_TRIS(ad, r, t) {
        const uint32_t *tri = ad->tris + 3 * t;
        area += tri_area(ad->x_rest, tri[0], tri[1], tri[2]);
      }
      FOR_ROOT_TRIS(ad, r, t) {
        const uint32_t *tri = ad->tris + 3 * t;
        double w = mu * tri_area(ad->x_rest, tri[0], tri[1], tri[2]) / (3 * area);
        for (int k = 0; k < 3; k++) ad->mass[tri[k]] += w;
      }
    }
  }
  /* Home springs and dampers follow the node mass: k_h / m stays that of
   * the coarse node (the same acceleration, the principle behind eq.
   * 5.15), so the home stiffness per unit area - what a probe feels - is
   * what it was. */
  size_t count = 0;
  double msum = 0;
  for (size_t q = 0; q < ad->nmodv + (ad->n - n0); q++) {
    size_t i = q < ad->nmodv ? ad->modv[q] : n0 + (q - ad->nmodv);
    msum += ad->mass[i];
    count++;
  }
  if (p->mass_rule == ADAPT_MASS_UNIFORM) {
    for (size_t i = 0; i < ad->n; i++) {
      ad->kh[i] = p->home_stiffness * ad->mass[i] / ad->m0;
      ad->ch[i] = p->home_damping * ad->mass[i] / ad->m0;
      ad->inv_mass[i] = ad->fixed[i] ? 0 : 1.0 / ad->mass[i];
    }
  }
  for (size_t q = 0; q < ad->nmodv + (ad->n - n0); q++) {
    size_t i = q < ad->nmodv ? ad->modv[q] : n0 + (q - ad->nmodv);
    if (!(ad->mass[i] > 0) || !isfinite(ad->mass[i])) {
      ad->failed = 1;
      return;
    }
    ad->kh[i] = p->home_stiffness * ad->mass[i] / ad->m0;
    ad->ch[i] = p->home_damping * ad->mass[i] / ad->m0;
    ad->inv_mass[i] = ad->fixed[i] ? 0 : 1.0 / ad->mass[i];
  }
  if (p->home_rule == ADAPT_HOME_MATCH) match_home(ad);
  /* New springs. */
  double ratio = count ? (msum / (double)count) / ad->m0 : 1;
  for (size_t s = ad->s0; s < ad->ns; s++) {
    ad_spring_t *sp = &ad->springs[s];
    if (p->k_rule == ADAPT_K_THESIS) {
      /* Eq. 5.15 (eq. 5.16 with SLoD = 4: red splits are complete): the
       * level l of a spring is the deepest level of its end nodes; mean
       * masses over the refined region after and before (equal coarse
       * masses: m0). Eq. 5.17: damping scaled with the stiffness. */
      int l = ad->vlevel[sp->i] > ad->vlevel[sp->j] ? ad->vlevel[sp->i] : ad->vlevel[sp->j];
      double scale = (double)(1u << l) * ratio;
      sp->k = p->stiffness * scale;
      sp->c = p->damping * scale;
    } else {
      /* A triangle lattice of springs k has membrane stiffness ~k whatever
       * the edge length: a red split (3 interior springs, 6 half edges) stores
       * the same energy under the same strain with the same k. The 2^l of
       * eq. 5.15 is the rule for springs in series (a chain), which would
       * make the refined patch 2^l times stiffer in the plane. */
      sp->k = p->stiffness;
      sp->c = p->damping;
    }
  }
  /* Time step, eq. 5.18: h = h_coarse / 2^l for the refined level (masses
   * ~4^-l at level l and unchanged spring stiffness give omega ~2^l). That
   * holds where stiffness limits the step; dashpots limit it as c / m ~ 4^l
   * and nodes bordering two levels can be stiffer still, so the fine
   * nodes' Gershgorin bound (node_bound, damping included: h^2 l_k +
   * 2 h l_c < 4, the coarse 0.9 margin) raises the ratio when eq. 5.18 is
   * not enough (at the default materials it is at level 2, not at level 3
   * and beyond, and not at 10x damping). The fine nodes are the vertices of
   * the refined faces; their coarse neighbours are held during the
   * sub-cycle, so the bound over their rows is the one that applies. */
  int l = ad->max_level;
  ad->nfine = 0;
  for (size_t q = 0; q < ad->nmodv + (ad->n - n0); q++) {
    size_t i = q < ad->nmodv ? ad->modv[q] : n0 + (q - ad->nmodv);
    ad->ksum[i] = ad->csum[i] = 0;
    ad->fine[i] = 1;
    ad->fine_nodes[ad->nfine++] = (uint32_t)i;
  }
  ad->nfine_springs = 0;
  for (size_t s = ad->s0; s < ad->ns; s++) {
    const ad_spring_t *sq = &ad->springs[s];
    ad->ksum[sq->i] += sq->k;
    ad->ksum[sq->j] += sq->k;
    ad->csum[sq->i] += sq->c;
    ad->csum[sq->j] += sq->c;
    ad->fine_springs[ad->nfine_springs++] = (uint32_t)s;
  }
  /* Coarse springs still on at the fine coarse nodes: into their sums
   * (stamped per node) and, once each (stamped UINT32_MAX), into the
   * fine spring list. */
  double lk = 0, lc = 0;
  uint32_t token = 0;
  for (size_t q = 0; q < ad->nfine; q++) {
    size_t i = ad->fine_nodes[q];
    if (i < n0) {
      token++;
      for (uint32_t a = ad->vf_off[i]; a < ad->vf_off[i + 1]; a++) {
        uint32_t g = ad->vf_idx[a];
        for (int k = 0; k < 3; k++) {
          uint32_t s = ad->fspr0[3 * (size_t)g + k];
          const ad_spring_t *sp = &ad->springs[s];
          /* One word per spring: 0 unseen; else listed, and last seen by
           * the node whose mark it holds (each edge is met from two faces). */
          uint32_t mark = UINT32_MAX - token;
          if ((sp->i != i && sp->j != i) || ad->spring_off[s] || ad->stamp[s] == mark) continue;
          if (ad->stamp[s] == 0) ad->fine_springs[ad->nfine_springs++] = s;
          ad->stamp[s] = mark;
          ad->ksum[i] += sp->k;
          ad->csum[i] += sp->c;
        }
      }
    }
    node_bound(ad, i, &lk, &lc);
  }
  /* Clear the stamps of the coarse springs around the region for the next
   * refinement. */
  for (size_t q = 0; q < ad->nmodv; q++) {
    uint32_t i = ad->modv[q];
    for (uint32_t a = ad->vf_off[i]; a < ad->vf_off[i + 1]; a++)
      for (int k = 0; k < 3; k++) ad->stamp[ad->fspr0[3 * (size_t)ad->vf_idx[a] + k]] = 0;
  }
  int ratio_fine = 1 << l;
  double h = damped_bound(lk, lc), hc = ad->dt / ad->substeps0;
  if (h > 0 && isfinite(h)) {
    double need = ceil(hc / (0.9 * h));
    if (need > ratio_fine) ratio_fine = need > 1e5 ? 100000 : (int)need;
  }
  ad->fine_ratio = ratio_fine;
  ad->substeps = ad->substeps0 * ratio_fine;
}

/* Back to the coarse mesh from any state, including a refinement that
 * failed half-way: every structure touched is listed (roots, disabled
 * springs, modified vertices, hash slots). Coarse vertices keep x and v. */
static void restore_coarse(adaptive_t *ad) {
  for (size_t r = 0; r < ad->nroots; r++) {
    uint32_t f = ad->root_face[r];
    memcpy(ad->tris + 3 * (size_t)f, ad->tris0 + 3 * (size_t)f, 3 * sizeof(uint32_t));
    ad->tri_face[f] = f;
    ad->face_root[f] = ADAPT_NONE;
  }
  for (size_t d = 0; d < ad->ndisabled; d++) ad->spring_off[ad->disabled[d]] = 0;
  size_t nrestore = ad->p.mass_rule == ADAPT_MASS_UNIFORM ? ad->n0 : ad->nmodv;
  for (size_t q = 0; q < nrestore; q++) {
    size_t i = ad->p.mass_rule == ADAPT_MASS_UNIFORM ? q : ad->modv[q];
    ad->mass[i] = ad->m0;
    ad->kh[i] = ad->p.home_stiffness;
    ad->ch[i] = ad->p.home_damping;
    ad->inv_mass[i] = ad->fixed[i] ? 0 : 1.0 / ad->m0;
  }
  for (size_t q = 0; q < ad->nmodv; q++) ad->vflag[ad->modv[q]] = 0;
  for (size_t q = 0; q < ad->nfine; q++) ad->fine[ad->fine_nodes[q]] = 0;
  ad->nfine = ad->nfine_springs = 0;
  ad->fine_ratio = 1;
  hash_clear(&ad->mid);
  hash_clear(&ad->edge);
  ad->n = ad->n0;
  ad->nt = ad->t0;
  ad->ns = ad->s0;
  ad->nroots = ad->nnodes = ad->ndisabled = ad->nmodv = 0;
  ad->max_level = 0;
  ad->substeps = ad->substeps0;
  ad->home_match = 1;
  ad->failed = 0;
}

static double now_us(void) { return (double)vtime_mono_ns() * 1e-3; }

int adaptive_refine(adaptive_t *ad, uint32_t c) {
  if (c >= ad->n0) return -1;
  adaptive_simplify(ad);
  double t0 = now_us();
  ad->failed = 0;
  ad->centre = c;
  for (uint32_t a = ad->vf_off[c]; a < ad->vf_off[c + 1]; a++) add_root(ad, ad->vf_idx[a]);
  size_t nstar = ad->nroots;
  for (size_t r = 0; r < nstar && !ad->failed; r++) mark(ad, ad->root_node[r]);
  balance(ad);
  int split = ad->nnodes > ad->nroots;
  if (!ad->failed && split) emit(ad);
  if (!ad->failed && split) build_springs(ad);
  if (!ad->failed && split) identify(ad);
  int failed = ad->failed;
  if (failed || !split) restore_coarse(ad);
  /* Remember the centre even when nothing changed or capacity ran out, so
   * the same contact does not retry every step. */
  ad->refined = 1;
  ad->topo_changed = split && !failed;
  ad->centre = c;
  if (failed) ad->capacity_failures++;
  if (ad->topo_changed) {
    ad->topology_version++;
    ad->refinements++;
    ad->last_refine_us = now_us() - t0;
  }
  return failed ? -1 : 0;
}

void adaptive_simplify(adaptive_t *ad) {
  if (!ad->refined) return;
  double t0 = now_us();
  int changed = ad->topo_changed;
  restore_coarse(ad);
  ad->refined = 0;
  ad->topo_changed = 0;
  ad->centre = ADAPT_NONE;
  ad->release_timer = 0;
  if (changed) {
    ad->topology_version++;
    ad->simplifications++;
    ad->last_simplify_us = now_us() - t0;
  }
}

/* -------------------------------------------------------------- stepping */

void adaptive_add_force(adaptive_t *ad, uint32_t i, const double f[3]) {
  if (i >= ad->n) return;
  if (!ad->is_forced[i]) {
    ad->is_forced[i] = 1;
    ad->forced[ad->nforced++] = i;
  }
  v3_add(ad->f_ext + 3 * (size_t)i, ad->f_ext + 3 * (size_t)i, f);
  double mag = v3_norm(f);
  if (ad->step_touched == ADAPT_NONE || !(mag <= ad->step_touched_mag)) {
    ad->step_touched = i;
    ad->step_touched_mag = mag;
  }
}

void adaptive_forces(const adaptive_t *ad, const double *x, const double *v, double *f) {
  const double *g = ad->p.gravity;
  for (size_t i = 0; i < ad->n; i++) {
    const double *xi = x + 3 * i, *vi = v + 3 * i, *xr = ad->x_rest + 3 * i;
    for (int k = 0; k < 3; k++)
      f[3 * i + k] = ad->f_ext[3 * i + k] + ad->mass[i] * g[k] - ad->kh[i] * (xi[k] - xr[k]) - ad->ch[i] * vi[k];
  }
  for (size_t s = 0; s < ad->ns; s++) {
    if (s < ad->s0 && ad->spring_off[s]) continue;
    const ad_spring_t *sp = &ad->springs[s];
    double d[3], dv[3];
    v3_sub(d, x + 3 * (size_t)sp->j, x + 3 * (size_t)sp->i);
    double len = v3_normalize(d);
    if (len <= 1e-300) continue; /* no direction: push nothing, stay finite */
    v3_sub(dv, v + 3 * (size_t)sp->j, v + 3 * (size_t)sp->i);
    /* Eq. 5.3: spring on the length change, dashpot on the relative
     * velocity along the spring (Kelvin-Voigt: in parallel). */
    double mag = sp->k * (len - sp->rest) + sp->c * v3_dot(dv, d);
    v3_axpy(f + 3 * (size_t)sp->i, d, mag);
    v3_axpy(f + 3 * (size_t)sp->j, d, -mag);
  }
}

static int in_star(const adaptive_t *ad, uint32_t centre, uint32_t c) {
  if (c == centre) return 1;
  for (uint32_t a = ad->vf_off[centre]; a < ad->vf_off[centre + 1]; a++) {
    const uint32_t *t = ad->tris0 + 3 * (size_t)ad->vf_idx[a];
    if (t[0] == c || t[1] == c || t[2] == c) return 1;
  }
  return 0;
}

/* External forces are cleared node by node (the list of forced nodes), so a
 * fine sub-step costs the region, not the mesh. */
static void clear_forced(adaptive_t *ad) {
  for (size_t q = 0; q < ad->nforced; q++) {
    uint32_t i = ad->forced[q];
    v3_set(ad->f_ext + 3 * (size_t)i, 0, 0, 0);
    ad->is_forced[i] = 0;
  }
  ad->nforced = 0;
}

/* Forces on the fine nodes, with the coarse neighbours where they are. */
static void fine_forces(adaptive_t *ad) {
  const double *g = ad->p.gravity;
  for (size_t q = 0; q < ad->nfine; q++) {
    size_t i = ad->fine_nodes[q];
    const double *xi = ad->x + 3 * i, *vi = ad->v + 3 * i, *xr = ad->x_rest + 3 * i;
    for (int k = 0; k < 3; k++)
      ad->ffine[3 * i + k] =
          ad->f_ext[3 * i + k] + ad->mass[i] * g[k] - ad->kh[i] * (xi[k] - xr[k]) - ad->ch[i] * vi[k];
  }
  for (size_t q = 0; q < ad->nfine_springs; q++) {
    const ad_spring_t *sp = &ad->springs[ad->fine_springs[q]];
    double d[3], dv[3];
    v3_sub(d, ad->x + 3 * (size_t)sp->j, ad->x + 3 * (size_t)sp->i);
    double len = v3_normalize(d);
    if (len <= 1e-300) continue;
    v3_sub(dv, ad->v + 3 * (size_t)sp->j, ad->v + 3 * (size_t)sp->i);
    double mag = sp->k * (len - sp->rest) + sp->c * v3_dot(dv, d);
    if (ad->fine[sp->i]) v3_axpy(ad->ffine + 3 * (size_t)sp->i, d, mag);
    if (ad->fine[sp->j]) v3_axpy(ad->ffine + 3 * (size_t)sp->j, d, -mag);
  }
}

static inline void kick_drift(adaptive_t *ad, size_t i, const double *f, double h) {
  /* Eq. 5.8-5.9: v <- v + h F / m, then x <- x + h v with the new v. */
  double w = ad->inv_mass[i] * h;
  for (int k = 0; k < 3; k++) {
    size_t c = 3 * i + k;
    ad->v[c] += w * f[c];
    ad->x[c] += h * ad->v[c];
  }
}

/* The nodes list[0..count) (all n when list is NULL) take one sub-step of h:
 * with declared tool springs, the kick of every node, then the springs'
 * implicit correction (coupling.h, inverse masses im: 0 for a node held),
 * then the drift; without, the fused kick-drift. */
static void advance(adaptive_t *ad, const uint32_t *list, size_t count, const double *f, double h, const double *im) {
  if (!ad->cpl || ad->cpl->n == 0) {
    for (size_t a = 0; a < count; a++) kick_drift(ad, list ? list[a] : a, f, h);
    return;
  }
  for (size_t a = 0; a < count; a++) {
    size_t i = list ? list[a] : a;
    v3_axpy(ad->v + 3 * i, f + 3 * i, ad->inv_mass[i] * h);
  }
  coupling_set_apply(ad->cpl, im, h, ad->v);
  for (size_t a = 0; a < count; a++) {
    size_t i = list ? list[a] : a;
    v3_axpy(ad->x + 3 * i, ad->v + 3 * i, h);
  }
}

/* Whether a declared spring is attached at a coarse node: only then does
 * the coarse step's implicit solve (fine nodes held) change anything. */
static int couples_coarse(const adaptive_t *ad) {
  const coupling_set_t *cs = ad->cpl;
  if (!cs) return 0;
  for (size_t c = 0; c < cs->n; c++)
    for (uint32_t l = 0; l < cs->s[c].nb; l++)
      if (!ad->fine[cs->node[cs->s[c].b0 + l]]) return 1;
  return 0;
}

int adaptive_step(adaptive_t *ad, double h, adaptive_pre_fn pre, void *ctx) {
  model_guard_save(&ad->guard, ad->x, ad->v, ad->n, NULL);
  int sc = ad->substeps0 < 1 ? 1 : ad->substeps0, r = ad->nfine ? ad->fine_ratio : 1;
  double hc = h / sc, hf = hc / r;
  ad->step_touched = ADAPT_NONE;
  ad->step_touched_mag = 0;
  if (r > 1)
    for (size_t a = 0; a < ad->nfine; a++) ad->im_fine[ad->fine_nodes[a]] = ad->inv_mass[ad->fine_nodes[a]];
  for (int s = 0; s < sc; s++) {
    if (r == 1) {
      if (pre) pre(ctx);
      adaptive_forces(ad, ad->x, ad->v, ad->f);
      clear_forced(ad);
      advance(ad, NULL, ad->n, ad->f, hc, ad->inv_mass);
      continue;
    }
    /* Multi-rate (eq. 5.18 for the refined level only): the coarse nodes'
     * forces at the start of the sub-step; the fine nodes sub-cycle r times
     * against them held; external forces on coarse nodes are averaged over
     * the sub-cycle; then the coarse nodes take their step. */
    clear_forced(ad);
    adaptive_forces(ad, ad->x, ad->v, ad->f);
    for (int q = 0; q < r; q++) {
      if (pre) pre(ctx);
      fine_forces(ad);
      advance(ad, ad->fine_nodes, ad->nfine, ad->ffine, hf, ad->im_fine);
      for (size_t a = 0; a < ad->nforced; a++) {
        uint32_t i = ad->forced[a];
        if (!ad->fine[i]) v3_axpy(ad->f + 3 * (size_t)i, ad->f_ext + 3 * (size_t)i, 1.0 / r);
      }
      clear_forced(ad);
    }
    if (!couples_coarse(ad)) {
      for (size_t i = 0; i < ad->n; i++)
        if (!ad->fine[i]) kick_drift(ad, i, ad->f, hc);
      continue;
    }
    /* A tool spring on coarse nodes too (a patch reaching past the refined
     * region, or the proxy on a coarse triangle before the region follows
     * it): the last sub-cycle's springs implicitly over the coarse nodes,
     * the fine ones held (their inverse mass 0 for the solve, then restored
     * from im_fine). */
    for (size_t i = 0; i < ad->n; i++)
      if (!ad->fine[i]) v3_axpy(ad->v + 3 * i, ad->f + 3 * i, ad->inv_mass[i] * hc);
    for (size_t a = 0; a < ad->nfine; a++) ad->inv_mass[ad->fine_nodes[a]] = 0;
    coupling_set_apply(ad->cpl, ad->inv_mass, hc, ad->v);
    for (size_t a = 0; a < ad->nfine; a++) ad->inv_mass[ad->fine_nodes[a]] = ad->im_fine[ad->fine_nodes[a]];
    for (size_t i = 0; i < ad->n; i++)
      if (!ad->fine[i]) v3_axpy(ad->x + 3 * i, ad->v + 3 * i, hc);
  }
  if (r > 1)
    for (size_t a = 0; a < ad->nfine; a++) ad->im_fine[ad->fine_nodes[a]] = 0;
  if (model_guard_check(&ad->guard, ad->x, ad->v, ad->n, NULL, NULL)) return -1;
  /* Topology after the step, so the forces of this step went to the mesh
   * they were computed for. */
  if (ad->p.refine_levels > 0 && ad->step_touched != ADAPT_NONE && ad->step_touched_mag >= ad->p.refine_force &&
      ad->step_touched_mag > 0) {
    ad->release_timer = 0;
    uint32_t c = ad->step_touched;
    uint32_t cc = c < ad->n0 ? c : ad->anchor[c - ad->n0];
    /* Hysteresis: while the touched node stays in the refined star, the
     * refinement stays; beyond it the region moves (simplify, refine). */
    if (!ad->refined || !in_star(ad, ad->centre, cc)) adaptive_refine(ad, cc);
  } else if (ad->refined) {
    ad->release_timer += h;
    if (ad->release_timer >= ad->p.release_time) adaptive_simplify(ad);
  }
  return 0;
}

double adaptive_energy(const adaptive_t *ad) {
  double e = 0;
  for (size_t i = 0; i < ad->n; i++) {
    double d[3];
    v3_sub(d, ad->x + 3 * i, ad->x_rest + 3 * i);
    e += 0.5 * ad->mass[i] * v3_dot(ad->v + 3 * i, ad->v + 3 * i) + 0.5 * ad->kh[i] * v3_dot(d, d) -
         ad->mass[i] * v3_dot(ad->p.gravity, ad->x + 3 * i);
  }
  for (size_t s = 0; s < ad->ns; s++) {
    if (s < ad->s0 && ad->spring_off[s]) continue;
    const ad_spring_t *sp = &ad->springs[s];
    double l = v3_dist(ad->x + 3 * (size_t)sp->i, ad->x + 3 * (size_t)sp->j) - sp->rest;
    e += 0.5 * sp->k * l * l;
  }
  return e;
}

double adaptive_max_strain(const adaptive_t *ad) {
  double worst = 0;
  for (size_t s = 0; s < ad->ns; s++) {
    if (s < ad->s0 && ad->spring_off[s]) continue;
    const ad_spring_t *sp = &ad->springs[s];
    if (!(sp->rest > 0)) continue;
    double e = fabs(v3_dist(ad->x + 3 * (size_t)sp->i, ad->x + 3 * (size_t)sp->j) / sp->rest - 1);
    if (e > worst) worst = e;
  }
  return worst;
}

double adaptive_total_mass(const adaptive_t *ad) {
  double m = 0;
  for (size_t i = 0; i < ad->n; i++) m += ad->mass[i];
  return m;
}

uint32_t adaptive_locate(const adaptive_t *ad, uint32_t face, const double p[3], double bary[3]) {
  if (face >= ad->t0) return ADAPT_NONE;
  uint32_t r = ad->face_root[face], best = face;
  double best_d = INFINITY;
  size_t count = r == ADAPT_NONE ? 0 : ad->root_count[r];
  for (size_t q = 0; q <= count; q++) {
    uint32_t t = q == 0 ? face : ad->root_first[r] + (uint32_t)q - 1;
    const uint32_t *tri = ad->tris + 3 * (size_t)t;
    double cp[3], b[3];
    tri_closest_point(p, ad->x + 3 * (size_t)tri[0], ad->x + 3 * (size_t)tri[1], ad->x + 3 * (size_t)tri[2], cp, b);
    double d = v3_dist(cp, p);
    if (d < best_d) {
      best_d = d;
      best = t;
      if (bary) v3_copy(bary, b);
    }
  }
  return best;
}
