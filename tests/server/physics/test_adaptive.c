/* SPDX-License-Identifier: Apache-2.0 */
/* Adaptive area-based refinement of a surface Kelvin-Voigt mass-spring
 * (docs/methods.md B ch. 5): refinement raises the local triangle count without
 * T-junctions (every edge in two triangles, orientation kept, springs =
 * edges), total mass is conserved to 1e-12, the force for the same
 * indentation matches before and after refinement, simplification restores
 * the coarse mesh, random centres never exceed the capacity, the model
 * interface publishes topology changes, and refine/simplify times are
 * printed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "mesh.h"
#include "mesh_import.h"
#include "physics/adaptive.h"
#include "physics/model.h"
#include "test_assets.h"
#include "vmath.h"
#include "vtime.h"

static adaptive_params_t params(double refine_area, int levels) {
  adaptive_params_t p = {.mass = 0.1,
                         .stiffness = 30,
                         .damping = 0.02,
                         .home_stiffness = 30,
                         .home_damping = 0.005,
                         .refine_area = refine_area,
                         .refine_levels = levels,
                         .refine_force = ADAPT_DEFAULT_REFINE_FORCE,
                         .release_time = ADAPT_DEFAULT_RELEASE_TIME,
                         .tool_stiffness = 300};
  return p;
}

/* A pointer to fresh parameters, for one call. */
#define PARAMS(area, levels) ((adaptive_params_t[]){params(area, levels)})

static int cmp_u64(const void *a, const void *b) {
  uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return (x > y) - (x < y);
}

static double rest_volume(const adaptive_t *ad) {
  mesh_t m = {.nverts = ad->n, .ntris = ad->nt, .pos = ad->x_rest, .tris = ad->tris};
  return mesh_signed_volume(&m);
}

typedef struct topo {
  double volume, boundary_len;
  long euler;
} topo_t;

/* Conformity and consistency of the current mesh. Each directed edge once;
 * an edge whose reverse is missing is an open boundary edge, and their total
 * length must be the coarse boundary's (a T-junction leaves unpaired edges
 * inside). Springs on = the undirected edges, exactly. Every vertex used,
 * every triangle of positive rest area, everything finite. */
static int check_mesh(const adaptive_t *ad, topo_t *out) {
  int bad = 0;
  size_t ne = 3 * ad->nt;
  uint64_t *e = malloc(ne * sizeof(uint64_t)), *u = malloc(ne * sizeof(uint64_t));
  uint8_t *used = calloc(ad->n, 1);
  size_t nu = 0;
  for (size_t t = 0; t < ad->nt; t++) {
    const uint32_t *tri = ad->tris + 3 * t;
    for (int k = 0; k < 3; k++) {
      uint32_t a = tri[k], b = tri[(k + 1) % 3];
      if (a >= ad->n || b >= ad->n || a == b) {
        bad++;
        continue;
      }
      used[a] = 1;
      e[3 * t + k] = ((uint64_t)a << 32) | b;
      if (a < b) u[nu++] = e[3 * t + k];
    }
    double n[3], e1[3], e2[3];
    v3_sub(e1, ad->x_rest + 3 * tri[1], ad->x_rest + 3 * tri[0]);
    v3_sub(e2, ad->x_rest + 3 * tri[2], ad->x_rest + 3 * tri[0]);
    v3_cross(n, e1, e2);
    bad += !(v3_norm(n) > 0);
  }
  qsort(e, ne, sizeof *e, cmp_u64);
  double blen = 0;
  size_t nedges = 0;
  for (size_t q = 0; q < ne; q++) {
    if (q > 0 && e[q] == e[q - 1]) bad++; /* a directed edge twice: orientation or overlap broken */
    uint32_t a = (uint32_t)(e[q] >> 32), b = (uint32_t)e[q];
    uint64_t rev = ((uint64_t)b << 32) | a;
    if (!bsearch(&rev, e, ne, sizeof *e, cmp_u64)) {
      blen += v3_dist(ad->x_rest + 3 * (size_t)a, ad->x_rest + 3 * (size_t)b);
      nedges++; /* boundary edge: counted once */
    } else if (a < b) {
      nedges++;
    }
  }
  for (size_t i = 0; i < ad->n; i++) bad += !used[i] || !v3_isfinite(ad->x + 3 * i) || !v3_isfinite(ad->v + 3 * i);
  /* Springs on, as sorted pairs, against the interior and boundary edges. */
  size_t nsp = 0;
  uint64_t *s = malloc((ad->ns + 1) * sizeof(uint64_t));
  for (size_t q = 0; q < ad->ns; q++) {
    if (q < ad->s0 && ad->spring_off[q]) continue;
    uint32_t a = ad->springs[q].i, b = ad->springs[q].j;
    s[nsp++] = a < b ? ((uint64_t)a << 32) | b : ((uint64_t)b << 32) | a;
    bad += !(ad->springs[q].k >= 0) || !(ad->springs[q].rest > 0);
  }
  /* Undirected edges: paired ones from u (a < b), plus boundary ones. */
  size_t nund = 0;
  uint64_t *und = malloc((ne + 1) * sizeof(uint64_t));
  for (size_t q = 0; q < ne; q++) {
    uint32_t a = (uint32_t)(e[q] >> 32), b = (uint32_t)e[q];
    uint64_t rev = ((uint64_t)b << 32) | a;
    int paired = bsearch(&rev, e, ne, sizeof *e, cmp_u64) != NULL;
    if (paired && a > b) continue;
    und[nund++] = a < b ? e[q] : rev;
  }
  qsort(und, nund, sizeof *und, cmp_u64);
  qsort(s, nsp, sizeof *s, cmp_u64);
  bad += nsp != nund || memcmp(s, und, nsp * sizeof *s) != 0;
  out->volume = rest_volume(ad);
  out->boundary_len = blen;
  out->euler = (long)ad->n - (long)nedges + (long)ad->nt;
  free(e);
  free(u);
  free(used);
  free(s);
  free(und);
  return bad;
}

static int same_topo(const topo_t *a, const topo_t *b) {
  return a->euler == b->euler && fabs(a->volume - b->volume) <= 1e-12 * fabs(b->volume) + 1e-18 &&
         fabs(a->boundary_len - b->boundary_len) <= 1e-12 * b->boundary_len + 1e-15;
}

static int cmp_dbl(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(double *v, int n) {
  qsort(v, (size_t)n, sizeof *v, cmp_dbl);
  return v[n / 2];
}

static double maxof(const double *v, int n) {
  double m = v[0];
  for (int i = 1; i < n; i++) m = fmax(m, v[i]);
  return m;
}

static double rel_mass_err(const adaptive_t *ad) { return fabs(adaptive_total_mass(ad) - ad->p.mass) / ad->p.mass; }

static double star_min_area(const adaptive_t *ad, uint32_t c) {
  double m = INFINITY;
  for (uint32_t a = ad->vf_off[c]; a < ad->vf_off[c + 1]; a++) m = fmin(m, ad->area0[ad->vf_idx[a]]);
  return m;
}

static int in_star_face(const adaptive_t *ad, uint32_t c, uint32_t face) {
  for (uint32_t a = ad->vf_off[c]; a < ad->vf_off[c + 1]; a++)
    if (ad->vf_idx[a] == face) return 1;
  return 0;
}

/* Refine around one spleen vertex: local count up, conforming, mass exact,
 * eq. 5.18 sub-steps; simplify back exactly; time both. */
static void test_refine_simplify(void) {
  mesh_t m;
  if (test_mesh_load("spleen.obj", &m)) {
    CHECK(0);
    return;
  }
  adaptive_t ad;
  verr_t err;
  CHECK(adaptive_create(&ad, &m, PARAMS(1, 2), 1e-3, 0, &err) == 0);
  uint32_t c = 123;
  ad.p.refine_area = 0.2 * star_min_area(&ad, c); /* every star face to level 2 */
  topo_t t0, t1;
  CHECK(check_mesh(&ad, &t0) == 0);
  CHECK(t0.euler == 2 && t0.boundary_len == 0);
  double *x0 = malloc(3 * m.nverts * sizeof(double));
  memcpy(x0, ad.x, 3 * m.nverts * sizeof(double));
  size_t nstar = ad.vf_off[c + 1] - ad.vf_off[c];
  CHECK(adaptive_refine(&ad, c) == 0);
  CHECK(ad.topology_version == 1 && ad.max_level == 2);
  size_t local = 0;
  for (size_t t = 0; t < ad.nt; t++) local += in_star_face(&ad, c, ad.tri_face[t]);
  CHECK(local == 16 * nstar); /* each one-ring face split 1-to-4 twice */
  CHECK(ad.nt > ad.t0 && ad.n > ad.n0);
  CHECK(check_mesh(&ad, &t1) == 0);
  CHECK(same_topo(&t1, &t0));
  CHECK(rel_mass_err(&ad) <= 1e-12);
  CHECK(ad.substeps >= ad.substeps0 * 4);
  printf("spleen refine at %u: %zu star faces -> %zu triangles there; mesh %zu -> %zu triangles, %zu -> %zu "
         "vertices, %zu -> %zu springs (%zu coarse off), %zu faces rooted; mass error %.2g; sub-steps %d -> %d; "
         "%.1f us\n",
         c, nstar, local, ad.t0, ad.nt, ad.n0, ad.n, ad.s0, ad.ns - ad.ndisabled, ad.ndisabled, ad.nroots,
         rel_mass_err(&ad), ad.substeps0, ad.substeps, ad.last_refine_us);
  /* Locating a point on a refined coarse face finds one of its pieces. */
  const uint32_t *ft = ad.tris0 + 3 * (size_t)ad.vf_idx[ad.vf_off[c]];
  double p[3], bary[3];
  for (int k = 0; k < 3; k++)
    p[k] = (ad.x_rest[3 * ft[0] + k] + 2 * ad.x_rest[3 * ft[1] + k] + 3 * ad.x_rest[3 * ft[2] + k]) / 6;
  uint32_t face = ad.vf_idx[ad.vf_off[c]], tri = adaptive_locate(&ad, face, p, bary);
  CHECK(tri < ad.nt && adaptive_tri_face(&ad, tri) == face);
  CHECK_NEAR(bary[0] + bary[1] + bary[2], 1, 1e-12);
  double q[3] = {0, 0, 0};
  for (int k = 0; k < 3; k++) v3_axpy(q, ad.x + 3 * (size_t)ad.tris[3 * (size_t)tri + k], bary[k]);
  CHECK(v3_dist(q, p) < 1e-12);

  adaptive_simplify(&ad);
  CHECK(ad.topology_version == 2);
  CHECK(ad.nt == ad.t0 && ad.n == ad.n0 && ad.ns == ad.s0 && ad.substeps == ad.substeps0);
  CHECK(memcmp(ad.tris, m.tris, 3 * m.ntris * sizeof(uint32_t)) == 0);
  CHECK(memcmp(ad.x, x0, 3 * m.nverts * sizeof(double)) == 0);
  int masses_back = 1;
  for (size_t i = 0; i < ad.n; i++) masses_back &= ad.mass[i] == ad.m0 && ad.kh[i] == ad.p.home_stiffness;
  CHECK(masses_back);
  CHECK(check_mesh(&ad, &t1) == 0 && same_topo(&t1, &t0));

  /* Timing: median of repeated refine / simplify pairs. */
  enum { R = 201 };
  static double tr[R], ts[R];
  for (int k = 0; k < R; k++) {
    uint64_t a = vtime_mono_ns();
    adaptive_refine(&ad, c);
    uint64_t b = vtime_mono_ns();
    adaptive_simplify(&ad);
    uint64_t d = vtime_mono_ns();
    tr[k] = (double)(b - a) * 1e-3;
    ts[k] = (double)(d - b) * 1e-3;
  }
  for (int i = 1; i < R; i++) /* insertion sort, small */
    for (int j = i; j > 0 && tr[j] < tr[j - 1]; j--) {
      double x = tr[j];
      tr[j] = tr[j - 1];
      tr[j - 1] = x;
    }
  for (int i = 1; i < R; i++)
    for (int j = i; j > 0 && ts[j] < ts[j - 1]; j--) {
      double x = ts[j];
      ts[j] = ts[j - 1];
      ts[j - 1] = x;
    }
  printf("spleen level 2: refine median %.1f us (p95 %.1f), simplify median %.1f us (p95 %.1f)\n", tr[R / 2],
         tr[R * 95 / 100], ts[R / 2], ts[R * 95 / 100]);
  free(x0);
  adaptive_destroy(&ad);
  mesh_free(&m);
}

/* Random centres on two organs at every level with a threshold below every
 * face (full depth): conforming, mass exact, capacity never exceeded,
 * simplification exact each time. */
static void test_random_centres(const char *name, int levels_max, int trials) {
  mesh_t m;
  if (test_mesh_load(name, &m)) {
    CHECK(0);
    return;
  }
  for (int L = 1; L <= levels_max; L++) {
    adaptive_t ad;
    verr_t err;
    CHECK(adaptive_create(&ad, &m, PARAMS(1e-12, L), 1e-3, 0, &err) == 0);
    topo_t t0, t1;
    CHECK(check_mesh(&ad, &t0) == 0);
    unsigned seed = 77u + (unsigned)L;
    int bad = 0;
    double worst_mass = 0, *t_ref = calloc((size_t)trials, sizeof(double)),
           *t_simp = calloc((size_t)trials, sizeof(double));
    size_t max_t = 0, max_roots = 0;
    int max_sub = 0;
    for (int k = 0; k < trials; k++) {
      seed = seed * 1664525u + 1013904223u;
      uint32_t c = (seed >> 8) % (uint32_t)ad.n0;
      bad += adaptive_refine(&ad, c) != 0;
      t_ref[k] = ad.last_refine_us;
      bad += ad.max_level != L;
      bad += check_mesh(&ad, &t1) != 0 || !same_topo(&t1, &t0);
      worst_mass = fmax(worst_mass, rel_mass_err(&ad));
      if (ad.nt > max_t) max_t = ad.nt;
      if (ad.nroots > max_roots) max_roots = ad.nroots;
      if (ad.substeps > max_sub) max_sub = ad.substeps;
      adaptive_simplify(&ad);
      t_simp[k] = ad.last_simplify_us;
      bad += ad.nt != ad.t0 || ad.n != ad.n0 || memcmp(ad.tris, m.tris, 3 * m.ntris * sizeof(uint32_t)) != 0;
    }
    CHECK(bad == 0);
    CHECK(worst_mass <= 1e-12);
    CHECK(ad.capacity_failures == 0);
    CHECK(max_roots <= ad.cap_roots && max_t <= ad.cap_t);
    printf("%s L=%d: %d centres, conforming, mass error <= %.1e, largest %zu triangles (capacity %zu), roots <= %zu "
           "(capacity %zu), fine sub-steps %d -> <= %d (eq. 5.18: %d), refine median %.1f us (max %.1f), simplify "
           "median %.1f us (max %.1f)\n",
           name, L, trials, worst_mass, max_t, ad.cap_t, max_roots, ad.cap_roots, ad.substeps0, max_sub,
           ad.substeps0 << L, median(t_ref, trials), maxof(t_ref, trials), median(t_simp, trials),
           maxof(t_simp, trials));
    free(t_ref);
    free(t_simp);
    adaptive_destroy(&ad);
  }
  mesh_free(&m);
}

/* The static force to push the touched node's one-ring (the star) rigidly
 * by delta along its inward normal, everything else free: pinned nodes are
 * all nodes on the star faces. */
static double indent_force(adaptive_t *ad, uint32_t c, double delta, int refine) {
  if (refine) adaptive_refine(ad, c);
  ad->p.release_time = 1e9; /* keep the refinement while relaxing */
  double nrm[3] = {0, 0, 0};
  for (uint32_t a = ad->vf_off[c]; a < ad->vf_off[c + 1]; a++) {
    const uint32_t *t = ad->tris0 + 3 * (size_t)ad->vf_idx[a];
    double e1[3], e2[3], cr[3];
    v3_sub(e1, ad->x_rest + 3 * t[1], ad->x_rest + 3 * t[0]);
    v3_sub(e2, ad->x_rest + 3 * t[2], ad->x_rest + 3 * t[0]);
    v3_cross(cr, e1, e2);
    v3_add(nrm, nrm, cr);
  }
  v3_normalize(nrm);
  uint8_t *pin = calloc(ad->n, 1);
  double *saved = malloc(ad->n * sizeof(double));
  for (size_t t = 0; t < ad->nt; t++)
    if (in_star_face(ad, c, ad->tri_face[t]))
      for (int k = 0; k < 3; k++) pin[ad->tris[3 * t + k]] = 1;
  for (size_t i = 0; i < ad->n; i++) {
    saved[i] = ad->inv_mass[i];
    if (!pin[i]) continue;
    ad->inv_mass[i] = 0;
    for (int k = 0; k < 3; k++) ad->x[3 * i + k] = ad->x_rest[3 * i + k] - delta * nrm[k];
    v3_set(ad->v + 3 * i, 0, 0, 0);
  }
  for (int s = 0; s < 20000; s++) {
    CHECK(adaptive_step(ad, 1e-3, NULL, NULL) == 0);
    double vmax = 0;
    for (size_t i = 0; i < 3 * ad->n; i++) vmax = fmax(vmax, fabs(ad->v[i]));
    if (vmax < 1e-9) break;
  }
  double *f = calloc(3 * ad->n, sizeof(double));
  adaptive_forces(ad, ad->x, ad->v, f);
  double force = 0;
  for (size_t i = 0; i < ad->n; i++)
    if (pin[i]) force += v3_dot(f + 3 * i, nrm); /* internal forces push back out: the probe supplies the rest */
  for (size_t i = 0; i < ad->n; i++) ad->inv_mass[i] = saved[i];
  free(f);
  free(pin);
  free(saved);
  return force;
}

/* Force-controlled probe as the runtime applies it (scene_runtime.c
 * build_patch): F spread over the vertices within r of the contact point
 * with weights (1 - d/r)^2, r = 1.5 mean coarse edge. Returns the felt
 * stiffness F / (displacement of the contact point along the normal). */
typedef struct probe_ctx {
  adaptive_t *ad;
  const double *w; /* per vertex of the mesh as it was when the probe started */
  size_t n;
  double wsum, F, nrm[3];
} probe_ctx_t;

static void probe_pre(void *ctx) {
  probe_ctx_t *p = ctx;
  for (size_t i = 0; i < p->n; i++)
    if (p->w[i] > 0) {
      double f[3];
      v3_scale(f, p->nrm, -p->F * p->w[i] / p->wsum);
      adaptive_add_force(p->ad, (uint32_t)i, f);
    }
}

static double probe_stiffness(adaptive_t *ad, uint32_t c, double F, int refine) {
  if (refine)
    adaptive_refine(ad, c);
  else
    ad->p.refine_force = INFINITY; /* the probe's own force would refine it */
  ad->p.release_time = 1e9;
  double mean_edge = 0;
  for (size_t q = 0; q < ad->s0; q++) mean_edge += ad->springs[q].rest / (double)ad->s0;
  double r = 1.5 * mean_edge, nrm[3] = {0, 0, 0};
  for (uint32_t a = ad->vf_off[c]; a < ad->vf_off[c + 1]; a++) {
    const uint32_t *t = ad->tris0 + 3 * (size_t)ad->vf_idx[a];
    double e1[3], e2[3], cr[3];
    v3_sub(e1, ad->x_rest + 3 * t[1], ad->x_rest + 3 * t[0]);
    v3_sub(e2, ad->x_rest + 3 * t[2], ad->x_rest + 3 * t[0]);
    v3_cross(cr, e1, e2);
    v3_add(nrm, nrm, cr);
  }
  v3_normalize(nrm);
  double *w = calloc(ad->n, sizeof(double)), sum = 0;
  for (size_t i = 0; i < ad->n; i++) {
    double d = v3_dist(ad->x_rest + 3 * i, ad->x_rest + 3 * (size_t)c);
    if (d < r) sum += w[i] = (1 - d / r) * (1 - d / r);
  }
  probe_ctx_t pc = {ad, w, ad->n, sum, F, {nrm[0], nrm[1], nrm[2]}};
  for (int s = 0; s < 20000; s++) {
    CHECK(adaptive_step(ad, 1e-3, probe_pre, &pc) == 0);
    double vmax = 0;
    for (size_t q = 0; q < 3 * ad->n; q++) vmax = fmax(vmax, fabs(ad->v[q]));
    if (s > 100 && vmax < 1e-9) break;
  }
  double d[3];
  v3_sub(d, ad->x + 3 * (size_t)c, ad->x_rest + 3 * (size_t)c);
  free(w);
  return F / -v3_dot(d, nrm);
}

static void test_indentation(void) {
  mesh_t m;
  if (test_mesh_load("spleen.obj", &m)) {
    CHECK(0);
    return;
  }
  static const struct {
    adapt_mass_rule_t mass;
    adapt_k_rule_t k;
    adapt_home_rule_t home;
    const char *name;
  } V[] = {
      {ADAPT_MASS_AREA, ADAPT_K_MEMBRANE, ADAPT_HOME_MASS, "mass area, springs membrane, home by mass (default)"},
      {ADAPT_MASS_AREA, ADAPT_K_MEMBRANE, ADAPT_HOME_MATCH, "mass area, springs membrane, home matched"},
      {ADAPT_MASS_AREA, ADAPT_K_THESIS, ADAPT_HOME_MATCH, "mass area, springs eq. 5.15-5.17, home matched"},
      {ADAPT_MASS_AREA, ADAPT_K_THESIS, ADAPT_HOME_MASS, "mass area, springs eq. 5.15-5.17, home by mass"},
      {ADAPT_MASS_UNIFORM, ADAPT_K_MEMBRANE, ADAPT_HOME_MASS, "mass eq. 5.10-5.11, springs membrane, home by mass"},
      {ADAPT_MASS_UNIFORM, ADAPT_K_THESIS, ADAPT_HOME_MASS, "mass eq. 5.10-5.11, springs eq. 5.15-5.17, home by mass"},
  };
  uint32_t centres[3] = {123, 300, 471};
  double delta = 0.002;
  for (size_t vi = 0; vi < sizeof V / sizeof V[0]; vi++) {
    double worst = 0, worst_probe = 0;
    for (int ci = 0; ci < 3; ci++) {
      adaptive_params_t p = params(1, 2);
      p.damping = 0.2; /* faster settling; statics do not depend on damping */
      p.home_damping = 0.05;
      p.mass_rule = V[vi].mass;
      p.k_rule = V[vi].k;
      p.home_rule = V[vi].home;
      adaptive_t ad;
      CHECK(adaptive_create(&ad, &m, &p, 1e-3, 0, NULL) == 0);
      uint32_t c = centres[ci];
      ad.p.refine_area = 0.2 * star_min_area(&ad, c);
      double f0 = indent_force(&ad, c, delta, 0);
      adaptive_destroy(&ad);
      CHECK(adaptive_create(&ad, &m, &p, 1e-3, 0, NULL) == 0);
      ad.p.refine_area = 0.2 * star_min_area(&ad, c);
      double f1 = indent_force(&ad, c, delta, 1);
      CHECK(ad.max_level == 2 && rel_mass_err(&ad) <= 1e-12);
      double rel = (f1 - f0) / f0;
      if (fabs(rel) > fabs(worst)) worst = rel;
      if (vi == 0 || vi == 1) {
        CHECK(ad.refined);
        adaptive_destroy(&ad);
        CHECK(adaptive_create(&ad, &m, &p, 1e-3, 0, NULL) == 0);
        ad.p.refine_area = 0.2 * star_min_area(&ad, c);
        double k0 = probe_stiffness(&ad, c, 0.2, 0);
        adaptive_destroy(&ad);
        CHECK(adaptive_create(&ad, &m, &p, 1e-3, 0, NULL) == 0);
        ad.p.refine_area = 0.2 * star_min_area(&ad, c);
        double k1 = probe_stiffness(&ad, c, 0.2, 1), pr = (k1 - k0) / k0;
        if (fabs(pr) > fabs(worst_probe)) worst_probe = pr;
        printf("  at %u: probe 0.2 N, felt stiffness coarse %.1f N/m, level 2 %.1f N/m (%+.1f %%); one-ring pushed "
               "%.0f mm: coarse %.4f N, level 2 %.4f N (%+.1f %%)\n",
               c, k0, k1, 100 * pr, 1e3 * delta, f0, f1, 100 * rel);
        /* The criterion: what the haptic user feels. */
        if (vi == 0) CHECK(fabs(pr) <= 0.10);
      }
      adaptive_destroy(&ad);
    }
    if (vi <= 1)
      printf("%s: probe stiffness worst change %+.1f %%, one-ring push force worst change %+.1f %%\n", V[vi].name,
             100 * worst_probe, 100 * worst);
    else
      printf("%s: one-ring push force worst change %+.1f %%\n", V[vi].name, 100 * worst);
  }
  mesh_free(&m);
}

/* Through model.h: contact refines after the step, topology_version and
 * the surface counts follow, moving the contact re-centres, release
 * simplifies, NaN rolls back without touching the topology. */
typedef struct hook_ctx {
  uint32_t node;
  double f[3];
  int on;
} hook_ctx_t;

static void model_hook(model_t *m, void *ctx) {
  hook_ctx_t *h = ctx;
  if (h->on) m->ops->add_surface_force(m, h->node, h->f);
}

static void test_model(void) {
  mesh_t m;
  if (test_mesh_load("spleen.obj", &m)) {
    CHECK(0);
    return;
  }
  double mean_area = 0;
  for (size_t t = 0; t < m.ntris; t++) {
    const uint32_t *f = m.tris + 3 * t;
    double e1[3], e2[3], cr[3];
    v3_sub(e1, m.pos + 3 * f[1], m.pos + 3 * f[0]);
    v3_sub(e2, m.pos + 3 * f[2], m.pos + 3 * f[0]);
    v3_cross(cr, e1, e2);
    mean_area += 0.5 * v3_norm(cr) / (double)m.ntris;
  }
  scene_organ_t cfg;
  memset(&cfg, 0, sizeof cfg);
  snprintf(cfg.name, sizeof cfg.name, "spleen");
  snprintf(cfg.model, sizeof cfg.model, "adaptive_mass_spring");
  snprintf(cfg.integrator, sizeof cfg.integrator, "symplectic_euler");
  cfg.material = (scene_material_t){.mass = 0.1,
                                    .stiffness = 30,
                                    .damping = 0.02,
                                    .home_stiffness = 30,
                                    .home_damping = 0.005,
                                    .refine_area = 0.3 * mean_area,
                                    .refine_levels = 2};
  model_params_t mp = {.cfg = &cfg, .surface = &m, .dt = 1e-3, .tool_stiffness = 300};
  verr_t err;
  model_t *md = model_adaptive_create(&mp, &err);
  CHECK(md != NULL);
  if (!md) {
    printf("%s\n", err.msg);
    mesh_free(&m);
    return;
  }
  adaptive_model_t *am = model_adaptive_of(md);
  CHECK(am != NULL && !strcmp(md->ops->name, "adaptive_mass_spring") && !strcmp(md->error_kind, "max_edge_strain"));
  CHECK(md->nsurf == m.nverts && md->nsurf_tris == m.ntris && md->topology_version == 0);
  const double *px = md->surf_x;
  const uint32_t *pt = md->surf_tris;
  int sub0 = md->substeps;
  hook_ctx_t h = {.node = 123, .f = {0, 0, -0.3}, .on = 1};
  md->hook = model_hook;
  md->hook_ctx = &h;
  CHECK(md->ops->step(md, 1e-3) == 0);
  CHECK(md->topology_version == 1 && md->nsurf > m.nverts && md->nsurf_tris > m.ntris);
  CHECK(md->nnodes == md->nsurf && md->substeps >= 2 * sub0 && md->surf_x == px && md->surf_tris == pt);
  int sub_refined = md->substeps;
  int rolled = 0;
  for (int s = 0; s < 500; s++) rolled += md->ops->step(md, 1e-3) != 0;
  CHECK(rolled == 0 && md->topology_version == 1);
  CHECK(isfinite(md->ops->energy(md)) && md->ops->error_estimate(md) > 0);
  double dmax = 0;
  for (size_t i = 0; i < md->nsurf; i++) dmax = fmax(dmax, v3_dist(md->surf_x + 3 * i, md->surf_rest + 3 * i));
  CHECK(dmax > 1e-3 && dmax < 0.05);
  topo_t t0, t1;
  CHECK(check_mesh(&am->ad, &t1) == 0);
  /* A touched node in the refined star keeps the refinement. */
  h.node = (uint32_t)(md->nsurf - 1);
  CHECK(md->ops->step(md, 1e-3) == 0 && md->topology_version == 1);
  /* Far away: simplify and refine there, one step. */
  h.node = 471;
  CHECK(md->ops->step(md, 1e-3) == 0 && md->topology_version == 3 && am->ad.centre == 471);
  /* NaN: rolled back, topology untouched. */
  size_t nt = md->nsurf_tris;
  h.f[2] = NAN;
  CHECK(md->ops->step(md, 1e-3) == -1 && md->rollbacks == 1 && md->topology_version == 3 && md->nsurf_tris == nt);
  h.f[2] = -0.3;
  /* Release: simplified after release_time, then the shape returns home. */
  h.on = 0;
  int steps_to_simplify = 0;
  while (md->topology_version == 3 && steps_to_simplify < 1000) {
    CHECK(md->ops->step(md, 1e-3) == 0);
    steps_to_simplify++;
  }
  CHECK(md->topology_version == 4 && md->nsurf == m.nverts && md->nsurf_tris == m.ntris && md->substeps == sub0);
  CHECK(memcmp(md->surf_tris, m.tris, 3 * m.ntris * sizeof(uint32_t)) == 0);
  CHECK(check_mesh(&am->ad, &t0) == 0 && same_topo(&t0, &t1));
  for (int s = 0; s < 5000; s++) md->ops->step(md, 1e-3);
  double back = 0;
  for (size_t i = 0; i < md->nsurf; i++) back = fmax(back, v3_dist(md->surf_x + 3 * i, md->surf_rest + 3 * i));
  CHECK(back < 1e-6);
  printf("model: refined on contact (sub-steps %d -> %d), simplified %d steps after release, back home within "
         "%.2g m after 5 s\n",
         sub0, sub_refined, steps_to_simplify, back);
  model_destroy(md);

  snprintf(cfg.integrator, sizeof cfg.integrator, "rk4");
  CHECK(model_adaptive_create(&mp, &err) == NULL && strstr(err.msg, "symplectic"));
  mesh_free(&m);
}

/* An open surface (the tissue block): boundary edges split on their own,
 * interior ones stay conforming. */
static void test_open_mesh(void) {
  mesh_t m;
  if (test_mesh_load("tissue_block.obj", &m)) {
    CHECK(0);
    return;
  }
  adaptive_t ad;
  CHECK(adaptive_create(&ad, &m, PARAMS(1e-12, 3), 1e-3, 0, NULL) == 0);
  topo_t t0, t1;
  CHECK(check_mesh(&ad, &t0) == 0);
  int bad = 0;
  for (uint32_t c = 0; c < ad.n0; c++) {
    bad += adaptive_refine(&ad, c) != 0;
    bad += check_mesh(&ad, &t1) != 0 || !same_topo(&t1, &t0) || rel_mass_err(&ad) > 1e-12;
    adaptive_simplify(&ad);
  }
  CHECK(bad == 0 && ad.capacity_failures == 0);
  printf("tissue block (open, boundary %.4f m): all %zu centres at level 3 conforming\n", t0.boundary_len, ad.n0);
  adaptive_destroy(&ad);
  mesh_free(&m);
}

static void test_refusals(void) {
  static const double P[5][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  static const uint32_t T[3][3] = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}}; /* edge 0-1 in three triangles */
  mesh_t m;
  mesh_alloc(&m, 5, 3, NULL);
  memcpy(m.pos, P, sizeof P);
  memcpy(m.tris, T, sizeof T);
  adaptive_t ad;
  verr_t err;
  CHECK(adaptive_create(&ad, &m, PARAMS(1e-3, 2), 1e-3, 0, &err) == -1 && strstr(err.msg, "manifold"));
  m.ntris = 2;
  CHECK(adaptive_create(&ad, &m, PARAMS(1e-3, 2), 1e-3, 0, &err) == 0);
  adaptive_destroy(&ad);
  CHECK(adaptive_create(&ad, &m, PARAMS(1e-3, ADAPT_MAX_LEVELS + 1), 1e-3, 0, &err) == -1);
  CHECK(adaptive_create(&ad, &m, PARAMS(0, 2), 1e-3, 0, &err) == -1 && strstr(err.msg, "refine_area"));
  adaptive_params_t p = params(1e-3, 2);
  p.mass = 0;
  CHECK(adaptive_create(&ad, &m, &p, 1e-3, 0, &err) == -1);
  m.pos[3 * 3 + 1] = 0; /* vertex 3 onto the line 0-1: a zero-area triangle */
  CHECK(adaptive_create(&ad, &m, PARAMS(1e-3, 2), 1e-3, 0, &err) == -1 && strstr(err.msg, "zero area"));
  mesh_free(&m);
}

/* Multi-rate stepping stays stable where eq. 5.18 alone would not: level 3,
 * ten times the damping, a contact force on the refined region, on two
 * organs. */
typedef struct push_ctx {
  adaptive_t *ad;
  uint32_t node;
  double f[3];
} push_ctx_t;

static void push_pre(void *ctx) {
  push_ctx_t *p = ctx;
  adaptive_add_force(p->ad, p->node, p->f);
}

static void test_stability(const char *name, int L) {
  mesh_t m;
  if (test_mesh_load(name, &m)) {
    CHECK(0);
    return;
  }
  static const double damp[2][2] = {{0.02, 0.005}, {0.2, 0.05}};
  for (int d = 0; d < 2; d++) {
    adaptive_params_t p = params(1e-12, L);
    p.damping = damp[d][0];
    p.home_damping = damp[d][1];
    adaptive_t ad;
    CHECK(adaptive_create(&ad, &m, &p, 1e-3, 0, NULL) == 0);
    push_ctx_t pc = {&ad, (uint32_t)(ad.n0 / 2), {0, 0, -0.3}};
    int rolled = 0;
    double dmax = 0;
    for (int s = 0; s < 150; s++) {
      rolled += adaptive_step(&ad, 1e-3, push_pre, &pc) != 0;
      if (s == 75) /* a new vertex of the refined one-ring: the refinement stays */
        for (size_t i = ad.n0; i < ad.n; i++)
          if (ad.anchor[i - ad.n0] == ad.centre) pc.node = (uint32_t)i;
    }
    for (size_t i = 0; i < ad.n; i++) dmax = fmax(dmax, v3_dist(ad.x + 3 * i, ad.x_rest + 3 * i));
    CHECK(rolled == 0 && ad.refined && ad.max_level == L);
    CHECK(dmax > 1e-4 && dmax < 0.05);
    printf("%s L=%d damping x%d: stable under 0.3 N (max displacement %.2f mm), coarse %d sub-steps, fine ratio %d "
           "(eq. 5.18: %d), %zu fine nodes\n",
           name, L, d ? 10 : 1, 1e3 * dmax, ad.substeps0, ad.fine_ratio, 1 << L, ad.nfine);
    adaptive_destroy(&ad);
  }
  mesh_free(&m);
}

/* Step cost through the model interface, default scene materials with
 * refine_levels 2 and refine_area 0.2 x the mesh's mean triangle area (the
 * scene default 2e-5 m^2 is above nearly every face of these meshes), coarse
 * and refined around a touched node. */
static void bench_steps(const char *name) {
  mesh_t m;
  if (test_mesh_load(name, &m)) {
    CHECK(0);
    return;
  }
  scene_organ_t cfg;
  memset(&cfg, 0, sizeof cfg);
  snprintf(cfg.name, sizeof cfg.name, "organ");
  snprintf(cfg.model, sizeof cfg.model, "adaptive_mass_spring");
  cfg.material = (scene_material_t){
      .mass = 0.1, .stiffness = 30, .damping = 0.02, .home_stiffness = 30, .home_damping = 0.005, .refine_levels = 2};
  for (size_t t = 0; t < m.ntris; t++) {
    const uint32_t *f = m.tris + 3 * t;
    double e1[3], e2[3], cr[3];
    v3_sub(e1, m.pos + 3 * f[1], m.pos + 3 * f[0]);
    v3_sub(e2, m.pos + 3 * f[2], m.pos + 3 * f[0]);
    v3_cross(cr, e1, e2);
    cfg.material.refine_area += 0.2 * 0.5 * v3_norm(cr) / (double)m.ntris;
  }
  model_params_t mp = {.cfg = &cfg, .surface = &m, .dt = 1e-3, .tool_stiffness = 300};
  model_t *md = model_adaptive_create(&mp, NULL);
  CHECK(md != NULL);
  if (!md) {
    mesh_free(&m);
    return;
  }
  adaptive_model_t *am = model_adaptive_of(md);
  hook_ctx_t h = {.node = (uint32_t)(m.nverts / 3), .f = {0, 0, -0.3}, .on = 0};
  md->hook = model_hook;
  md->hook_ctx = &h;
  enum { N = 301 };
  static double tc[N], tr[N];
  for (int s = 0; s < N; s++) {
    uint64_t t0 = vtime_mono_ns();
    md->ops->step(md, 1e-3);
    tc[s] = (double)(vtime_mono_ns() - t0) * 1e-3;
  }
  int sub_c = md->substeps;
  h.on = 1;
  md->ops->step(md, 1e-3); /* refines */
  CHECK(md->topology_version == 1 && am->ad.max_level == 2);
  for (int s = 0; s < N; s++) {
    uint64_t t0 = vtime_mono_ns();
    md->ops->step(md, 1e-3);
    tr[s] = (double)(vtime_mono_ns() - t0) * 1e-3;
  }
  printf("%s adaptive step (%zu vertices): coarse median %.1f us (%d sub-steps); refined to level %d (+%zu vertices, "
         "%zu fine nodes, %d coarse x %d fine sub-steps) median %.1f us; refine %.1f us\n",
         name, m.nverts, median(tc, N), sub_c, am->ad.max_level, am->ad.n - am->ad.n0, am->ad.nfine, am->ad.substeps0,
         am->ad.fine_ratio, median(tr, N), am->ad.last_refine_us);
  model_destroy(md);
  mesh_free(&m);
}

int main(void) {
  test_refine_simplify();
  test_indentation();
  test_model();
  test_open_mesh();
  test_refusals();
  test_random_centres("spleen.obj", 4, 120);
  test_random_centres("gallbladder.obj", 3, 40);
  test_stability("spleen.obj", 3);
  test_stability("kidney.obj", 2);
  bench_steps("spleen.obj");
  bench_steps("gallbladder.obj");
  return check_report("test_adaptive");
}
