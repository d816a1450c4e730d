/* SPDX-License-Identifier: Apache-2.0 */
#include "physics/pbd.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "vmath.h"

/* The four-wide sweeps (project_volume_x4, project_distance_x4) need GCC
 * or Clang on x86; elsewhere only the scalar loops are built. */
#if (defined(__x86_64__) || defined(__i386__)) && (defined(__GNUC__) || defined(__clang__))
#define PBD_HAVE_AVX2 1
#include <immintrin.h>
#else
#define PBD_HAVE_AVX2 0
#endif

/* Unique edges from the tetrahedra: sort (min,max) pairs and drop repeats.
 * Colouring keeps this order within each colour, so a sweep still walks
 * the nodes roughly in memory order. */
static int cmp_edge(const void *a, const void *b) {
  const uint32_t *x = a, *y = b;
  if (x[0] != y[0]) return x[0] < y[0] ? -1 : 1;
  return (x[1] > y[1]) - (x[1] < y[1]);
}

/* Greedy graph colouring of constraints (arity nodes each, idx[arity c + k])
 * into perm: constraints of colour 0 first, then 1, ..., each colour in its
 * original order. Within a colour no two constraints share a node, so the
 * Gauss-Seidel sweep has no dependency from one constraint to the next and
 * the CPU overlaps their square roots and divisions; in mesh order
 * neighbouring constraints share a node and each waits for the previous
 * one's update (1.7x slower on the BarDemo bar). The sweep stays
 * Gauss-Seidel (in place), only the order changes; colours also make the
 * four-wide sweeps possible. Up to 128 colours; the
 * rare constraint that finds none free shares the last one, which costs
 * speed, never correctness. Returns -1 on OOM. */
static int colour_order(size_t nc, int arity, const uint32_t *idx, size_t n, size_t *perm, size_t *start) {
  uint64_t(*used)[2] = calloc(n ? n : 1, sizeof *used);
  uint8_t *colour = malloc(nc ? nc : 1);
  size_t count[PBD_COLOURS + 1] = {0};
  if (!used || !colour) {
    free(used);
    free(colour);
    return -1;
  }
  for (size_t c = 0; c < nc; c++) {
    uint64_t m0 = 0, m1 = 0;
    for (int k = 0; k < arity; k++) {
      m0 |= used[idx[arity * c + k]][0];
      m1 |= used[idx[arity * c + k]][1];
    }
    int col = PBD_COLOURS - 1;
    if (~m0)
      col = __builtin_ctzll(~m0);
    else if (~m1)
      col = 64 + __builtin_ctzll(~m1);
    colour[c] = (uint8_t)col;
    for (int k = 0; k < arity; k++) used[idx[arity * c + k]][col >> 6] |= (uint64_t)1 << (col & 63);
    count[col + 1]++;
  }
  for (int k = 0; k < PBD_COLOURS; k++) count[k + 1] += count[k];
  memcpy(start, count, sizeof count);
  for (size_t c = 0; c < nc; c++) perm[count[colour[c]]++] = c;
  free(used);
  free(colour);
  return 0;
}

static int check_params(const pbd_params_t *p, verr_t *err) {
  if (p->mode != PBD_MODE_PBD && p->mode != PBD_MODE_XPBD) return verr_set(err, "pbd: unknown mode %d", (int)p->mode);
  if (!(p->mass > 0) || !isfinite(p->mass)) return verr_set(err, "pbd: mass must be > 0 (got %g)", p->mass);
  if (!(p->distance_stiffness >= 0 && p->distance_stiffness <= 1) ||
      !(p->volume_stiffness >= 0 && p->volume_stiffness <= 1))
    return verr_set(err, "pbd: stiffness must be in 0..1 (distance %g, volume %g)", p->distance_stiffness,
                    p->volume_stiffness);
  if (!(p->distance_compliance >= 0) || !(p->volume_compliance >= 0) || !isfinite(p->distance_compliance) ||
      !isfinite(p->volume_compliance))
    return verr_set(err, "pbd: compliance must be >= 0 (distance %g, volume %g)", p->distance_compliance,
                    p->volume_compliance);
  if (!(p->home_stiffness >= 0) || !isfinite(p->home_stiffness) || !(p->damping >= 0) || !isfinite(p->damping))
    return verr_set(err, "pbd: home_stiffness and damping must be >= 0");
  if (!v3_isfinite(p->gravity)) return verr_set(err, "pbd: gravity must be finite");
  if (p->substeps < 1 || p->iterations < 1)
    return verr_set(err, "pbd: substeps and iterations must be >= 1 (got %d, %d)", p->substeps, p->iterations);
  return 0;
}

/* Puts edges and tetrahedra in colour order (colour_order). */
static int reorder(pbd_t *s) {
  size_t nmax = s->nedges > s->ntets ? s->nedges : s->ntets;
  size_t *perm = malloc((nmax ? nmax : 1) * sizeof(size_t));
  uint32_t *ibuf = malloc(4 * (nmax ? nmax : 1) * sizeof(uint32_t));
  double *dbuf = malloc((nmax ? nmax : 1) * sizeof(double));
  int rc = -1;
  if (!perm || !ibuf || !dbuf) goto out;
  if (colour_order(s->nedges, 2, s->edge, s->n, perm, s->edge_colour)) goto out;
  for (size_t e = 0; e < s->nedges; e++) memcpy(ibuf + 2 * e, s->edge + 2 * perm[e], 2 * sizeof(uint32_t));
  memcpy(s->edge, ibuf, 2 * s->nedges * sizeof(uint32_t));
  for (size_t e = 0; e < s->nedges; e++) dbuf[e] = s->edge_rest[perm[e]];
  memcpy(s->edge_rest, dbuf, s->nedges * sizeof(double));
  if (colour_order(s->ntets, 4, s->tet, s->n, perm, s->tet_colour)) goto out;
  for (size_t t = 0; t < s->ntets; t++) memcpy(ibuf + 4 * t, s->tet + 4 * perm[t], 4 * sizeof(uint32_t));
  memcpy(s->tet, ibuf, 4 * s->ntets * sizeof(uint32_t));
  for (size_t t = 0; t < s->ntets; t++) dbuf[t] = s->tet_rest[perm[t]];
  memcpy(s->tet_rest, dbuf, s->ntets * sizeof(double));
  for (size_t t = 0; t < s->ntets; t++) dbuf[t] = s->tet_step2[perm[t]];
  memcpy(s->tet_step2, dbuf, s->ntets * sizeof(double));
  rc = 0;
out:
  free(perm);
  free(ibuf);
  free(dbuf);
  return rc;
}

/* pbd_create and pbd_create_edges: distance constraints from the tetrahedra's
 * edges and from `nextra` extra (i, j) pairs (either list may be empty, not
 * both). */
static int create(pbd_t *s, size_t n, const double *x, size_t ntets, const uint32_t *tets, size_t nextra,
                  const uint32_t *extra, const pbd_params_t *p, verr_t *err) {
  memset(s, 0, sizeof *s);
  if (check_params(p, err)) return -1;
  if (n == 0 || (ntets == 0 && nextra == 0))
    return verr_set(err, "pbd: empty mesh (%zu nodes, %zu tetrahedra, %zu edges)", n, ntets, nextra);
  if (n > UINT32_MAX) return verr_set(err, "pbd: too many nodes (%zu)", n);
  for (size_t t = 0; t < 4 * ntets; t++)
    if (tets[t] >= n) return verr_set(err, "pbd: tetrahedron %zu refers to node %u of %zu", t / 4, tets[t], n);
  for (size_t e = 0; e < 2 * nextra; e++)
    if (extra[e] >= n) return verr_set(err, "pbd: edge %zu refers to node %u of %zu", e / 2, extra[e], n);
  for (size_t c = 0; c < 3 * n; c++)
    if (!isfinite(x[c])) return verr_set(err, "pbd: node %zu has a non-finite coordinate", c / 3);
  s->p = *p;
  s->n = n;
  s->ntets = ntets;
  size_t n3 = 3 * n;
  s->x = calloc(n3, sizeof(double));
  s->v = calloc(n3, sizeof(double));
  s->x_rest = calloc(n3, sizeof(double));
  s->x_old = calloc(n3, sizeof(double));
  int guard_rc = model_guard_reserve(&s->guard, n);
  s->f_ext = calloc(n3, sizeof(double));
  s->home_lambda = calloc(n3, sizeof(double));
  s->inv_mass = calloc(n, sizeof(double));
  s->mass = calloc(n, sizeof(double));
  s->mark = calloc(n, 1);
  s->tet = malloc((4 * ntets + 1) * sizeof(uint32_t)); /* + 1: an edge-only mesh allocates too */
  s->tet_rest = calloc(ntets + 1, sizeof(double));
  s->tet_step2 = calloc(ntets + 1, sizeof(double));
  s->tet_lambda = calloc(ntets + 1, sizeof(double));
  s->tet_w = calloc(4 * ntets + 1, sizeof(double));
  uint32_t *edges = malloc((12 * ntets + 2 * nextra) * sizeof(uint32_t));
  if (!s->x || !s->v || !s->x_rest || !s->x_old || guard_rc || !s->f_ext || !s->home_lambda || !s->inv_mass ||
      !s->mass || !s->mark || !s->tet || !s->tet_rest || !s->tet_step2 || !s->tet_lambda || !s->tet_w || !edges) {
    free(edges);
    pbd_destroy(s);
    return verr_set(err, "pbd: out of memory for %zu nodes, %zu tetrahedra", n, ntets);
  }
  memcpy(s->x, x, n3 * sizeof(double));
  memcpy(s->x_rest, x, n3 * sizeof(double));
  if (ntets) memcpy(s->tet, tets, 4 * ntets * sizeof(uint32_t));
  /* Equal lumped masses, as in mass_spring.c: volume-weighted masses would
   * give the slivers of automatic meshes tiny masses and slow convergence. */
  for (size_t i = 0; i < n; i++) {
    s->mass[i] = p->mass / (double)n;
    s->inv_mass[i] = 1.0 / s->mass[i];
  }
  static const int E[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  for (size_t t = 0; t < ntets; t++) {
    const uint32_t *q = tets + 4 * t;
    double g[4][3];
    s->tet_rest[t] = (pbd_volume_constraint(x + 3 * q[0], x + 3 * q[1], x + 3 * q[2], x + 3 * q[3], 0, g)) / 6.0;
    s->rest_volume += s->tet_rest[t];
    double lsum = 0;
    for (int k = 0; k < 6; k++) {
      uint32_t i = q[E[k][0]], j = q[E[k][1]];
      lsum += v3_dist(x + 3 * i, x + 3 * j);
      edges[12 * t + 2 * k] = i < j ? i : j;
      edges[12 * t + 2 * k + 1] = i < j ? j : i;
    }
    /* One volume projection moves no node further than the tetrahedron's
     * mean rest edge. Near a needle (collinear nodes) the gradient vanishes
     * while C stays about -6 V0, and the unclamped move C / |grad| would
     * grow without bound: this cap keeps speeds bounded there, and never
     * acts on a tetrahedron near its rest shape. */
    double lm = lsum / 6;
    s->tet_step2[t] = lm * lm;
  }
  for (size_t e = 0; e < nextra; e++) {
    uint32_t i = extra[2 * e], j = extra[2 * e + 1];
    edges[12 * ntets + 2 * e] = i < j ? i : j;
    edges[12 * ntets + 2 * e + 1] = i < j ? j : i;
  }
  size_t ne = 6 * ntets + nextra;
  qsort(edges, ne, 2 * sizeof(uint32_t), cmp_edge);
  size_t unique = 0;
  for (size_t e = 0; e < ne; e++)
    if ((e == 0 || cmp_edge(edges + 2 * e, edges + 2 * (e - 1)) != 0) && edges[2 * e] != edges[2 * e + 1]) unique++;
  s->edge = malloc(2 * unique * sizeof(uint32_t));
  s->edge_rest = calloc(unique, sizeof(double));
  s->edge_lambda = calloc(unique, sizeof(double));
  s->edge_w = calloc(2 * unique, sizeof(double));
  s->edge_inv = calloc(unique, sizeof(double));
  if (!s->edge || !s->edge_rest || !s->edge_lambda || !s->edge_w || !s->edge_inv) {
    free(edges);
    pbd_destroy(s);
    return verr_set(err, "pbd: out of memory for %zu edges", unique);
  }
  for (size_t e = 0; e < ne; e++) {
    if (e > 0 && cmp_edge(edges + 2 * e, edges + 2 * (e - 1)) == 0) continue;
    uint32_t i = edges[2 * e], j = edges[2 * e + 1];
    if (i == j) continue; /* a tetrahedron naming a node twice has no such edge */
    size_t k = s->nedges++;
    s->edge[2 * k] = i;
    s->edge[2 * k + 1] = j;
    s->edge_rest[k] = v3_dist(x + 3 * i, x + 3 * j);
  }
  free(edges);
  s->cache_stale = 1;
#if PBD_HAVE_AVX2
  __builtin_cpu_init();
  s->simd = __builtin_cpu_supports("avx2");
#endif
  if (reorder(s)) {
    pbd_destroy(s);
    return verr_set(err, "pbd: out of memory ordering constraints");
  }
  return 0;
}

int pbd_create(pbd_t *s, size_t n, const double *x, size_t ntets, const uint32_t *tets, const pbd_params_t *p,
               verr_t *err) {
  if (ntets == 0) {
    memset(s, 0, sizeof *s);
    return verr_set(err, "pbd: empty mesh (%zu nodes, 0 tetrahedra)", n);
  }
  return create(s, n, x, ntets, tets, 0, NULL, p, err);
}

int pbd_create_edges(pbd_t *s, size_t n, const double *x, size_t nedges, const uint32_t *edges, const pbd_params_t *p,
                     verr_t *err) {
  if (nedges == 0) {
    memset(s, 0, sizeof *s);
    return verr_set(err, "pbd: no edges (%zu nodes)", n);
  }
  return create(s, n, x, 0, NULL, nedges, edges, p, err);
}

void pbd_destroy(pbd_t *s) {
  free(s->x);
  free(s->v);
  free(s->x_rest);
  free(s->x_old);
  model_guard_free(&s->guard);
  free(s->f_ext);
  free(s->home_lambda);
  free(s->inv_mass);
  free(s->mass);
  free(s->mark);
  free(s->tet);
  free(s->tet_rest);
  free(s->tet_step2);
  free(s->tet_lambda);
  free(s->edge);
  free(s->edge_rest);
  free(s->edge_lambda);
  free(s->edge_w);
  free(s->edge_inv);
  free(s->tet_w);
  free(s->edge_alpha_scale);
  memset(s, 0, sizeof *s);
}

void pbd_fix_node(pbd_t *s, size_t i) {
  if (i < s->n) {
    s->inv_mass[i] = 0;
    s->cache_stale = 1;
    for (int k = 0; k < 3; k++) s->v[3 * i + k] = 0;
  }
}

void pbd_set_node_mass(pbd_t *s, size_t i, double m) {
  if (i < s->n && m > 0 && isfinite(m)) {
    int fixed = s->inv_mass[i] == 0;
    s->mass[i] = m;
    if (!fixed) s->inv_mass[i] = 1.0 / m;
    s->cache_stale = 1;
  }
}

size_t pbd_fix_below(pbd_t *s, double z) {
  size_t count = 0;
  for (size_t i = 0; i < s->n; i++)
    if (s->x_rest[3 * i + 2] < z) {
      pbd_fix_node(s, i);
      count++;
    }
  return count;
}

/* Per-constraint copies of the inverse masses (and, for edges, of
 * 1 / (w_i + w_j + alpha~)), refreshed when masses or alpha~ change: the
 * sweeps then read them in order instead of through the node indices and
 * divide once less per edge (together about 15 % of a step). */
static void refresh_cache(pbd_t *s, double atd) {
  const double *w = s->inv_mass;
  if (s->cache_stale) {
    for (size_t t = 0; t < 4 * s->ntets; t++) s->tet_w[t] = w[s->tet[t]];
    for (size_t e = 0; e < 2 * s->nedges; e++) s->edge_w[e] = w[s->edge[e]];
  }
  if (s->cache_stale || !(atd == s->edge_inv_at)) {
    for (size_t e = 0; e < s->nedges; e++) {
      double ws = s->edge_w[2 * e] + s->edge_w[2 * e + 1] + atd;
      /* Both nodes fixed and the edge rigid: 0 makes dlambda 0. */
      s->edge_inv[e] = ws > 0 ? 1.0 / ws : 0;
    }
    s->edge_inv_at = atd;
  }
  s->cache_stale = 0;
}

/* Distance constraints e0 .. e1 - 1, one after the other. k scales C (the
 * PBD stiffness, 1 in XPBD) and at is alpha~ (0 in PBD), so one expression
 * serves both: dlambda = (-k C - alpha~ lambda) / (w_i + w_j + alpha~). */
static void project_distance_range(pbd_t *s, double k, double at, size_t e0, size_t e1) {
  double *restrict x = s->x, *restrict lam = s->edge_lambda;
  const double *restrict ew = s->edge_w, *restrict inv = s->edge_inv, *restrict rest = s->edge_rest,
                         *restrict xr = s->x_rest;
  const uint32_t *restrict edge = s->edge;
  for (size_t e = e0; e < e1; e++) {
    uint32_t i = edge[2 * e], j = edge[2 * e + 1];
    double *xi = x + 3 * i, *xj = x + 3 * j, nrm[3];
    double C = pbd_distance_constraint(xi, xj, rest[e], xr + 3 * i, xr + 3 * j, nrm);
    double dl = (-k * C - at * lam[e]) * inv[e];
    lam[e] += dl;
    double a = ew[2 * e] * dl, b = ew[2 * e + 1] * dl;
    xi[0] += a * nrm[0];
    xi[1] += a * nrm[1];
    xi[2] += a * nrm[2];
    xj[0] -= b * nrm[0];
    xj[1] -= b * nrm[1];
    xj[2] -= b * nrm[2];
  }
}

/* Volume constraints C = 6 (V - V0), same update as the distances, for
 * tetrahedra t0 .. t1 - 1 one after the other. Written out per node (no
 * small arrays or loops) so the compiler keeps everything in registers at
 * -O2. */
static void project_volume_range(pbd_t *s, double k, double at, size_t t0, size_t t1) {
  double *restrict x = s->x, *restrict lam = s->tet_lambda;
  const double *restrict tw = s->tet_w, *restrict rest = s->tet_rest, *restrict step2 = s->tet_step2;
  const uint32_t *restrict tet = s->tet;
  for (size_t t = t0; t < t1; t++) {
    const uint32_t *q = tet + 4 * t;
    double *p0 = x + 3 * q[0], *p1 = x + 3 * q[1], *p2 = x + 3 * q[2], *p3 = x + 3 * q[3];
    double w0 = tw[4 * t], w1 = tw[4 * t + 1], w2 = tw[4 * t + 2], w3 = tw[4 * t + 3];
    double ax = p1[0] - p0[0], ay = p1[1] - p0[1], az = p1[2] - p0[2];
    double bx = p2[0] - p0[0], by = p2[1] - p0[1], bz = p2[2] - p0[2];
    double cx = p3[0] - p0[0], cy = p3[1] - p0[1], cz = p3[2] - p0[2];
    /* grad_1 = b x c, grad_2 = c x a, grad_3 = a x b, grad_0 = -sum. */
    double g1x = by * cz - bz * cy, g1y = bz * cx - bx * cz, g1z = bx * cy - by * cx;
    double g2x = cy * az - cz * ay, g2y = cz * ax - cx * az, g2z = cx * ay - cy * ax;
    double g3x = ay * bz - az * by, g3y = az * bx - ax * bz, g3z = ax * by - ay * bx;
    double g0x = -(g1x + g2x + g3x), g0y = -(g1y + g2y + g3y), g0z = -(g1z + g2z + g3z);
    double C = (g3x * cx + g3y * cy + g3z * cz) - 6.0 * rest[t];
    double wg = w0 * (g0x * g0x + g0y * g0y + g0z * g0z) + w1 * (g1x * g1x + g1y * g1y + g1z * g1z) +
                w2 * (g2x * g2x + g2y * g2y + g2z * g2z) + w3 * (g3x * g3x + g3y * g3y + g3z * g3z);
    double denom = wg + at;
    /* Zero gradient (all nodes on one point or line), or all nodes fixed:
     * no direction to move in. */
    if (!(denom > 1e-300) || !(wg > 0)) continue;
    double dl = (-k * C - at * lam[t]) / denom;
    /* Node a moves |dl| w_a |g_a| <= |dl| sqrt(w_max wg): cap that bound at
     * the tetrahedron's size (tet_step2, see pbd_create). The bound is
     * cheaper than the exact maximum and equal to it for equal masses. */
    double wa = w0 > w1 ? w0 : w1, wb = w2 > w3 ? w2 : w3; /* not fmax(): a libm call at -O2 */
    double m2 = (wa > wb ? wa : wb) * wg;
    if (dl * dl * m2 > step2[t]) dl = copysign(sqrt(step2[t] / m2), dl);
    lam[t] += dl;
    double c0 = w0 * dl, c1 = w1 * dl, c2 = w2 * dl, c3 = w3 * dl;
    p0[0] += c0 * g0x;
    p0[1] += c0 * g0y;
    p0[2] += c0 * g0z;
    p1[0] += c1 * g1x;
    p1[1] += c1 * g1y;
    p1[2] += c1 * g1z;
    p2[0] += c2 * g2x;
    p2[1] += c2 * g2y;
    p2[2] += c2 * g2z;
    p3[0] += c3 * g3x;
    p3[1] += c3 * g3y;
    p3[2] += c3 * g3z;
  }
}

#if PBD_HAVE_AVX2
/* The volume sweep is most of a step's cost, and four tetrahedra of one
 * colour share no node: projecting them together is the same as one after
 * the other. On x86-64 CPUs with AVX2 (checked at run time, so the build
 * stays generic) this does four at once with GCC/Clang vector extensions,
 * about 1.5x faster than the scalar loop. The arithmetic is the scalar
 * loop's, operation for operation and in the same order (no FMA: ISO C
 * mode does not contract), so both paths give bit-identical results.
 * (Without AVX, two-lane SSE2 vectors were no faster: gathering lanes costs
 * what the arithmetic saves.) */
typedef double pbd_v4 __attribute__((vector_size(32)));
typedef long long pbd_m4 __attribute__((vector_size(32)));

__attribute__((target("avx2"))) static void project_volume_x4(pbd_t *s, double k, double at, size_t t0, size_t t1) {
  double *restrict x = s->x, *restrict lam = s->tet_lambda;
  const double *restrict tw = s->tet_w;
  for (size_t t = t0; t + 4 <= t1; t += 4) {
    const uint32_t *q = s->tet + 4 * t;
    double *r0[4] = {x + 3 * q[0], x + 3 * q[4], x + 3 * q[8], x + 3 * q[12]};
    double *r1[4] = {x + 3 * q[1], x + 3 * q[5], x + 3 * q[9], x + 3 * q[13]};
    double *r2[4] = {x + 3 * q[2], x + 3 * q[6], x + 3 * q[10], x + 3 * q[14]};
    double *r3[4] = {x + 3 * q[3], x + 3 * q[7], x + 3 * q[11], x + 3 * q[15]};
#define PBD_GATHER(r, c) ((pbd_v4){(r)[0][c], (r)[1][c], (r)[2][c], (r)[3][c]})
    pbd_v4 x0 = PBD_GATHER(r0, 0), y0 = PBD_GATHER(r0, 1), z0 = PBD_GATHER(r0, 2);
    pbd_v4 ax = PBD_GATHER(r1, 0) - x0, ay = PBD_GATHER(r1, 1) - y0, az = PBD_GATHER(r1, 2) - z0;
    pbd_v4 bx = PBD_GATHER(r2, 0) - x0, by = PBD_GATHER(r2, 1) - y0, bz = PBD_GATHER(r2, 2) - z0;
    pbd_v4 cx = PBD_GATHER(r3, 0) - x0, cy = PBD_GATHER(r3, 1) - y0, cz = PBD_GATHER(r3, 2) - z0;
#undef PBD_GATHER
    const double *W = tw + 4 * t;
    pbd_v4 w0 = {W[0], W[4], W[8], W[12]}, w1 = {W[1], W[5], W[9], W[13]};
    pbd_v4 w2 = {W[2], W[6], W[10], W[14]}, w3 = {W[3], W[7], W[11], W[15]};
    pbd_v4 g1x = by * cz - bz * cy, g1y = bz * cx - bx * cz, g1z = bx * cy - by * cx;
    pbd_v4 g2x = cy * az - cz * ay, g2y = cz * ax - cx * az, g2z = cx * ay - cy * ax;
    pbd_v4 g3x = ay * bz - az * by, g3y = az * bx - ax * bz, g3z = ax * by - ay * bx;
    pbd_v4 g0x = -(g1x + g2x + g3x), g0y = -(g1y + g2y + g3y), g0z = -(g1z + g2z + g3z);
    pbd_v4 rest, l0, step2;
    memcpy(&rest, s->tet_rest + t, sizeof rest);
    memcpy(&l0, lam + t, sizeof l0);
    memcpy(&step2, s->tet_step2 + t, sizeof step2);
    pbd_v4 C = (g3x * cx + g3y * cy + g3z * cz) - 6.0 * rest;
    pbd_v4 wg = w0 * (g0x * g0x + g0y * g0y + g0z * g0z) + w1 * (g1x * g1x + g1y * g1y + g1z * g1z) +
                w2 * (g2x * g2x + g2y * g2y + g2z * g2z) + w3 * (g3x * g3x + g3y * g3y + g3z * g3z);
    pbd_v4 denom = wg + at, one = {1, 1, 1, 1};
    /* Lanes the scalar loop skips divide by 1 and get dl = 0 (the mask),
     * which moves nothing. */
    pbd_m4 ok = (denom > 1e-300) & (wg > 0);
    pbd_v4 safe = (pbd_v4)(((pbd_m4)denom & ok) | ((pbd_m4)one & ~ok));
    pbd_v4 dl = (pbd_v4)((pbd_m4)((-k * C - at * l0) / safe) & ok);
    pbd_m4 s01 = w0 > w1, s23 = w2 > w3;
    pbd_v4 wa = (pbd_v4)(((pbd_m4)w0 & s01) | ((pbd_m4)w1 & ~s01));
    pbd_v4 wb = (pbd_v4)(((pbd_m4)w2 & s23) | ((pbd_m4)w3 & ~s23));
    pbd_m4 sab = wa > wb;
    pbd_v4 m2 = (pbd_v4)(((pbd_m4)wa & sab) | ((pbd_m4)wb & ~sab)) * wg;
    pbd_m4 cap = dl * dl * m2 > step2;
    if (cap[0] | cap[1] | cap[2] | cap[3])
      for (int l = 0; l < 4; l++)
        if (cap[l]) dl[l] = copysign(sqrt(step2[l] / m2[l]), dl[l]);
    l0 += dl;
    memcpy(lam + t, &l0, sizeof l0);
    pbd_v4 c0 = w0 * dl, c1 = w1 * dl, c2 = w2 * dl, c3 = w3 * dl;
    pbd_v4 d0x = c0 * g0x, d0y = c0 * g0y, d0z = c0 * g0z, d1x = c1 * g1x, d1y = c1 * g1y, d1z = c1 * g1z;
    pbd_v4 d2x = c2 * g2x, d2y = c2 * g2y, d2z = c2 * g2z, d3x = c3 * g3x, d3y = c3 * g3y, d3z = c3 * g3z;
#define PBD_SCATTER(r, dx, dy, dz, l) ((r)[l][0] += (dx)[l], (r)[l][1] += (dy)[l], (r)[l][2] += (dz)[l])
#define PBD_SCATTER_LANE(l)                                                                                            \
  (PBD_SCATTER(r0, d0x, d0y, d0z, l), PBD_SCATTER(r1, d1x, d1y, d1z, l), PBD_SCATTER(r2, d2x, d2y, d2z, l),            \
   PBD_SCATTER(r3, d3x, d3y, d3z, l))
    PBD_SCATTER_LANE(0);
    PBD_SCATTER_LANE(1);
    PBD_SCATTER_LANE(2);
    PBD_SCATTER_LANE(3);
#undef PBD_SCATTER_LANE
#undef PBD_SCATTER
  }
}

/* Four distance constraints of one colour at once, the same way; the
 * square root needs an intrinsic (vector extensions have none). A batch
 * with a zero-length edge goes through the scalar loop, which knows the
 * fallback direction. */
__attribute__((target("avx2"))) static void project_distance_x4(pbd_t *s, double k, double at, size_t e0, size_t e1) {
  double *restrict x = s->x, *restrict lam = s->edge_lambda;
  for (size_t e = e0; e + 4 <= e1; e += 4) {
    const uint32_t *q = s->edge + 2 * e;
    double *ri[4] = {x + 3 * q[0], x + 3 * q[2], x + 3 * q[4], x + 3 * q[6]};
    double *rj[4] = {x + 3 * q[1], x + 3 * q[3], x + 3 * q[5], x + 3 * q[7]};
#define PBD_GATHER(r, c) ((pbd_v4){(r)[0][c], (r)[1][c], (r)[2][c], (r)[3][c]})
    pbd_v4 d0 = PBD_GATHER(ri, 0) - PBD_GATHER(rj, 0), d1 = PBD_GATHER(ri, 1) - PBD_GATHER(rj, 1);
    pbd_v4 d2 = PBD_GATHER(ri, 2) - PBD_GATHER(rj, 2);
#undef PBD_GATHER
    pbd_v4 len = (pbd_v4)_mm256_sqrt_pd((__m256d)(d0 * d0 + d1 * d1 + d2 * d2));
    pbd_m4 ok = len > 1e-300;
    if (!(ok[0] & ok[1] & ok[2] & ok[3])) {
      project_distance_range(s, k, at, e, e + 4);
      continue;
    }
    pbd_v4 rest, l0, inv;
    memcpy(&rest, s->edge_rest + e, sizeof rest);
    memcpy(&l0, lam + e, sizeof l0);
    memcpy(&inv, s->edge_inv + e, sizeof inv);
    pbd_v4 il = 1.0 / len;
    pbd_v4 n0 = d0 * il, n1 = d1 * il, n2 = d2 * il;
    pbd_v4 C = len - rest;
    pbd_v4 dl = (-k * C - at * l0) * inv;
    l0 += dl;
    memcpy(lam + e, &l0, sizeof l0);
    const double *W = s->edge_w + 2 * e;
    pbd_v4 a = (pbd_v4){W[0], W[2], W[4], W[6]} * dl, b = (pbd_v4){W[1], W[3], W[5], W[7]} * dl;
    pbd_v4 ax = a * n0, ay = a * n1, az = a * n2, bx = b * n0, by = b * n1, bz = b * n2;
#define PBD_SCATTER_LANE(l)                                                                                            \
  (ri[l][0] += ax[l], ri[l][1] += ay[l], ri[l][2] += az[l], rj[l][0] -= bx[l], rj[l][1] -= by[l], rj[l][2] -= bz[l])
    PBD_SCATTER_LANE(0);
    PBD_SCATTER_LANE(1);
    PBD_SCATTER_LANE(2);
    PBD_SCATTER_LANE(3);
#undef PBD_SCATTER_LANE
  }
}
#endif

/* One sweep over all volume constraints: colour by colour, four at a time
 * where the CPU allows, the rest (and the overflow colour, whose members
 * may share nodes) one at a time. */
static void project_volumes(pbd_t *s, double k, double at) {
#if PBD_HAVE_AVX2
  if (s->simd) {
    for (int c = 0; c < PBD_COLOURS - 1; c++) {
      size_t t0 = s->tet_colour[c], t1 = s->tet_colour[c + 1], t4 = t0 + (t1 - t0) / 4 * 4;
      project_volume_x4(s, k, at, t0, t4);
      project_volume_range(s, k, at, t4, t1);
    }
    project_volume_range(s, k, at, s->tet_colour[PBD_COLOURS - 1], s->ntets);
    return;
  }
#endif
  project_volume_range(s, k, at, 0, s->ntets);
}

/* Distance constraints with per-edge compliance (edge_alpha_scale set):
 * alpha~_e = at * scale[e], so the cached 1 / (w_i + w_j + alpha~) does not
 * apply; one at a time, scalar (the uniform case keeps its fast sweeps). */
static void project_distance_scaled(pbd_t *s, double k, double at) {
  double *restrict x = s->x, *restrict lam = s->edge_lambda;
  const double *restrict ew = s->edge_w, *restrict rest = s->edge_rest, *restrict xr = s->x_rest,
                         *restrict sc = s->edge_alpha_scale;
  for (size_t e = 0; e < s->nedges; e++) {
    uint32_t i = s->edge[2 * e], j = s->edge[2 * e + 1];
    double *xi = x + 3 * i, *xj = x + 3 * j, nrm[3];
    double ate = at * sc[e], ws = ew[2 * e] + ew[2 * e + 1] + ate;
    if (!(ws > 0)) continue; /* both nodes fixed and the edge rigid */
    double C = pbd_distance_constraint(xi, xj, rest[e], xr + 3 * i, xr + 3 * j, nrm);
    double dl = (-k * C - ate * lam[e]) / ws;
    lam[e] += dl;
    v3_axpy(xi, nrm, ew[2 * e] * dl);
    v3_axpy(xj, nrm, -ew[2 * e + 1] * dl);
  }
}

/* One sweep over all distance constraints, the same way. */
static void project_distances(pbd_t *s, double k, double at) {
  if (s->edge_alpha_scale) {
    project_distance_scaled(s, k, at);
    return;
  }
#if PBD_HAVE_AVX2
  if (s->simd) {
    for (int c = 0; c < PBD_COLOURS - 1; c++) {
      size_t e0 = s->edge_colour[c], e1 = s->edge_colour[c + 1], e4 = e0 + (e1 - e0) / 4 * 4;
      project_distance_x4(s, k, at, e0, e4);
      project_distance_range(s, k, at, e4, e1);
    }
    project_distance_range(s, k, at, s->edge_colour[PBD_COLOURS - 1], s->nedges);
    return;
  }
#endif
  project_distance_range(s, k, at, 0, s->nedges);
}

/* Home springs as compliant zero-length constraints per axis, C = x - r,
 * gradient 1: dlambda = (-C - alpha~ lambda) / (w + alpha~). */
static void project_home(pbd_t *s, double at) {
  double *restrict x = s->x, *restrict lam = s->home_lambda;
  const double *restrict w = s->inv_mass, *restrict r = s->x_rest;
  size_t n = s->n;
  for (size_t i = 0; i < n; i++) {
    double wi = w[i];
    if (wi == 0) continue;
    double inv = 1.0 / (wi + at);
    for (int k = 0; k < 3; k++) {
      size_t c = 3 * i + k;
      double dl = (r[c] - x[c] - at * lam[c]) * inv;
      lam[c] += dl;
      x[c] += wi * dl;
    }
  }
}

static void substep(pbd_t *s, double h, double kd, double kv, double atd, double atv, double ath) {
  size_t n = s->n;
  double *restrict x = s->x, *restrict v = s->v, *restrict xo = s->x_old;
  const double *restrict w = s->inv_mass, *restrict fe = s->f_ext, *g = s->p.gravity;
  double c = s->p.damping;
  /* Predict. Ground damping scales the previous velocity by 1 / (1 + h c w)
   * (implicit, so stable for any c) before the external forces act: damping
   * the new gravity increment too would shrink the load every sub-step and
   * bias the static sag. */
  for (size_t i = 0; i < n; i++) {
    double wi = w[i];
    double *xi = x + 3 * i, *vi = v + 3 * i, *oi = xo + 3 * i;
    const double *fi = fe + 3 * i;
    oi[0] = xi[0];
    oi[1] = xi[1];
    oi[2] = xi[2];
    if (wi == 0) {
      vi[0] = vi[1] = vi[2] = 0;
      continue;
    }
    double damp = 1.0 / (1.0 + h * c * wi);
    for (int k = 0; k < 3; k++) {
      vi[k] = vi[k] * damp + h * (g[k] + wi * fi[k]);
      xi[k] += h * vi[k];
    }
  }
  /* XPBD resets the multipliers every sub-step; PBD keeps them only as
   * a diagnostic of the corrections, so the same reset serves both. */
  memset(s->edge_lambda, 0, s->nedges * sizeof(double));
  memset(s->tet_lambda, 0, s->ntets * sizeof(double));
  int home = s->p.home_stiffness > 0;
  if (home) memset(s->home_lambda, 0, 3 * n * sizeof(double));
  for (int it = 0; it < s->p.iterations; it++) {
    project_distances(s, kd, atd);
    project_volumes(s, kv, atv);
    if (home) project_home(s, ath);
  }
  double ih = 1.0 / h;
  for (size_t c3 = 0; c3 < 3 * n; c3++) v[c3] = (x[c3] - xo[c3]) * ih;
  /* Tool springs (pbd.h): the rank-one implicit solve on the sub-step's
   * velocity, then the moved nodes' positions from it. */
  if (s->cpl && s->cpl->n > 0) {
    coupling_set_apply(s->cpl, w, h, v);
    coupling_set_drift(s->cpl, w, h, xo, v, x);
  }
}

int pbd_step(pbd_t *s, double h, pbd_substep_fn pre, void *ctx) {
  size_t n3 = 3 * s->n;
  model_guard_save(&s->guard, s->x, s->v, s->n, NULL);
  int ns = s->p.substeps < 1 ? 1 : s->p.substeps, iters = s->p.iterations < 1 ? 1 : s->p.iterations;
  double hs = h / ns;
  double kd = 1, kv = 1, atd = 0, atv = 0;
  if (s->p.mode == PBD_MODE_PBD) {
    kd = s->p.distance_stiffness;
    kv = s->p.volume_stiffness;
    if (s->p.stiffness_correction) {
      kd = 1 - pow(1 - kd, 1.0 / iters);
      kv = 1 - pow(1 - kv, 1.0 / iters);
    }
  } else {
    atd = s->p.distance_compliance / (hs * hs);
    atv = s->p.volume_compliance / (hs * hs);
  }
  double ath = s->p.home_stiffness > 0 ? 1.0 / (s->p.home_stiffness * hs * hs) : 0;
  int ok = isfinite(hs) && hs > 0;
  if (ok) refresh_cache(s, atd);
  for (int k = 0; ok && k < ns; k++) {
    if (pre) pre(s, ctx);
    substep(s, hs, kd, kv, atd, atv, ath);
    memset(s->f_ext, 0, n3 * sizeof(double));
  }
  s->last_h = ok ? hs : 0;
  if ((ok ? model_guard_check(&s->guard, s->x, s->v, s->n, NULL, &s->rollbacks)
          : model_guard_rollback(&s->guard, s->x, s->v, &s->rollbacks)) == 0)
    return 0;
  memset(s->f_ext, 0, n3 * sizeof(double));
  /* The multipliers of a failed step mean nothing (and may be NaN). */
  memset(s->edge_lambda, 0, s->nedges * sizeof(double));
  memset(s->tet_lambda, 0, s->ntets * sizeof(double));
  memset(s->home_lambda, 0, n3 * sizeof(double));
  /* A node that was already non-finite before the call (injected from
   * outside) would fail every later step: it goes back to rest instead, so
   * nothing spreads and the next step can succeed. */
  for (size_t i = 0; i < s->n; i++)
    if (!v3_isfinite(s->x + 3 * i) || !v3_isfinite(s->v + 3 * i)) {
      v3_copy(s->x + 3 * i, s->x_rest + 3 * i);
      v3_set(s->v + 3 * i, 0, 0, 0);
    }
  return -1;
}

void pbd_errors(const pbd_t *s, pbd_errors_t *e) {
  memset(e, 0, sizeof *e);
  double s2 = 0;
  size_t ns = 0;
  for (size_t k = 0; k < s->nedges; k++) {
    double r = s->edge_rest[k];
    if (!(r > 0)) continue;
    double d = fabs(v3_dist(s->x + 3 * s->edge[2 * k], s->x + 3 * s->edge[2 * k + 1]) / r - 1);
    if (d > e->strain_max) e->strain_max = d;
    s2 += d * d;
    ns++;
  }
  e->strain_rms = ns ? sqrt(s2 / (double)ns) : 0;
  double vol = 0;
  e->min_volume = INFINITY;
  e->min_volume_ratio = INFINITY;
  for (size_t t = 0; t < s->ntets; t++) {
    const uint32_t *q = s->tet + 4 * t;
    double g[4][3];
    double V = pbd_volume_constraint(s->x + 3 * q[0], s->x + 3 * q[1], s->x + 3 * q[2], s->x + 3 * q[3], 0, g) / 6.0;
    vol += V;
    if (V < e->min_volume) e->min_volume = V;
    if (V <= 0) e->inverted++;
    double V0 = s->tet_rest[t];
    if (V0 > 0) {
      double r = V / V0;
      if (r < e->min_volume_ratio) e->min_volume_ratio = r;
      if (fabs(r - 1) > e->volume_worst) e->volume_worst = fabs(r - 1);
    }
  }
  e->volume_global = s->rest_volume > 0 ? fabs(vol / s->rest_volume - 1) : 0;
}

double pbd_volume_error(const pbd_t *s) {
  double vol = 0;
  for (size_t t = 0; t < s->ntets; t++) {
    const uint32_t *q = s->tet + 4 * t;
    double g[4][3];
    vol += pbd_volume_constraint(s->x + 3 * q[0], s->x + 3 * q[1], s->x + 3 * q[2], s->x + 3 * q[3], 0, g) / 6.0;
  }
  return s->rest_volume > 0 ? fabs(vol / s->rest_volume - 1) : 0;
}

double pbd_energy(const pbd_t *s) {
  double e = 0;
  for (size_t i = 0; i < s->n; i++) {
    e += 0.5 * s->mass[i] * v3_dot(s->v + 3 * i, s->v + 3 * i);
    if (s->inv_mass[i] > 0) e -= s->mass[i] * v3_dot(s->p.gravity, s->x + 3 * i);
    if (s->p.home_stiffness > 0) {
      double d[3];
      v3_sub(d, s->x + 3 * i, s->x_rest + 3 * i);
      e += 0.5 * s->p.home_stiffness * v3_dot(d, d);
    }
  }
  if (s->p.mode != PBD_MODE_XPBD) return e;
  if (s->p.distance_compliance > 0)
    for (size_t k = 0; k < s->nedges; k++) {
      double nrm[3];
      double C = pbd_distance_constraint(s->x + 3 * s->edge[2 * k], s->x + 3 * s->edge[2 * k + 1], s->edge_rest[k],
                                         s->x_rest + 3 * s->edge[2 * k], s->x_rest + 3 * s->edge[2 * k + 1], nrm);
      double a = s->p.distance_compliance * (s->edge_alpha_scale ? s->edge_alpha_scale[k] : 1);
      if (a > 0) e += C * C / (2 * a); /* a rigid edge (scale 0) stores nothing */
    }
  if (s->p.volume_compliance > 0)
    for (size_t t = 0; t < s->ntets; t++) {
      const uint32_t *q = s->tet + 4 * t;
      double g[4][3];
      double C =
          pbd_volume_constraint(s->x + 3 * q[0], s->x + 3 * q[1], s->x + 3 * q[2], s->x + 3 * q[3], s->tet_rest[t], g);
      e += C * C / (2 * s->p.volume_compliance);
    }
  return e;
}

double pbd_constraint_force(pbd_t *s, const uint32_t *nodes, size_t count, double f[3]) {
  double acc[3] = {0, 0, 0};
  if (s->last_h > 0) {
    for (size_t k = 0; k < count; k++)
      if (nodes[k] < s->n) s->mark[nodes[k]] = 1;
    double ih2 = 1.0 / (s->last_h * s->last_h);
    for (size_t e = 0; e < s->nedges; e++) {
      uint32_t i = s->edge[2 * e], j = s->edge[2 * e + 1];
      if (!s->mark[i] && !s->mark[j]) continue;
      double nrm[3];
      pbd_distance_constraint(s->x + 3 * i, s->x + 3 * j, s->edge_rest[e], s->x_rest + 3 * i, s->x_rest + 3 * j, nrm);
      double l = s->edge_lambda[e] * ih2;
      if (s->mark[i]) v3_axpy(acc, nrm, l);
      if (s->mark[j]) v3_axpy(acc, nrm, -l);
    }
    for (size_t t = 0; t < s->ntets; t++) {
      const uint32_t *q = s->tet + 4 * t;
      if (!s->mark[q[0]] && !s->mark[q[1]] && !s->mark[q[2]] && !s->mark[q[3]]) continue;
      double g[4][3];
      pbd_volume_constraint(s->x + 3 * q[0], s->x + 3 * q[1], s->x + 3 * q[2], s->x + 3 * q[3], s->tet_rest[t], g);
      double l = s->tet_lambda[t] * ih2;
      for (int a = 0; a < 4; a++)
        if (s->mark[q[a]]) v3_axpy(acc, g[a], l);
    }
    if (s->p.home_stiffness > 0)
      for (size_t i = 0; i < s->n; i++)
        if (s->mark[i]) v3_axpy(acc, s->home_lambda + 3 * i, ih2);
    for (size_t k = 0; k < count; k++)
      if (nodes[k] < s->n) s->mark[nodes[k]] = 0;
  }
  if (f) v3_copy(f, acc);
  return v3_norm(acc);
}

int pbd_set_edge_compliance_scale(pbd_t *s, const double *scale, verr_t *err) {
  if (!scale) {
    free(s->edge_alpha_scale);
    s->edge_alpha_scale = NULL;
    return 0;
  }
  for (size_t e = 0; e < s->nedges; e++)
    if (!(scale[e] >= 0) || !isfinite(scale[e]))
      return verr_set(err, "pbd: compliance factor of edge %zu must be finite and >= 0 (got %g)", e, scale[e]);
  double *a = realloc(s->edge_alpha_scale, (s->nedges + 1) * sizeof(double));
  if (!a) return verr_set(err, "pbd: out of memory for %zu compliance factors", s->nedges);
  memcpy(a, scale, s->nedges * sizeof(double));
  s->edge_alpha_scale = a;
  return 0;
}
