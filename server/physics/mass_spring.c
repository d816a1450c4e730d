/* SPDX-License-Identifier: Apache-2.0 */
#include "physics/mass_spring.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "physics/avx_rows.h"
#include "vmath.h"

/* Below this length a spring has no usable direction (v3_normalize's guard). */
#define MS_TINY 1e-300

/* The force_system callbacks: fs is the first member of mass_spring_t. */
static void fs_forces(force_system_t *s, const double *x, const double *v, double *f) {
  mass_spring_forces((const mass_spring_t *)s, x, v, f);
}
static void fs_stiffness_mul(force_system_t *s, const double *x, double a, double b, const double *y, double *out) {
  mass_spring_stiffness_mul((const mass_spring_t *)s, x, a, b, y, out);
}

static int ms_alloc(mass_spring_t *ms, size_t n, const double *pos, const ms_params_t *p, verr_t *err) {
  memset(ms, 0, sizeof *ms);
  if (!(p->mass > 0) || !isfinite(p->mass) || !(p->stiffness >= 0) || !(p->damping >= 0) || !(p->home_stiffness >= 0) ||
      !(p->home_damping >= 0) || !isfinite(p->stiffness) || !isfinite(p->damping) || !isfinite(p->home_stiffness) ||
      !isfinite(p->home_damping) || !v3_isfinite(p->gravity))
    return verr_set(err, "mass-spring: mass must be > 0 and stiffness/damping >= 0, all finite");
  if (n == 0) return verr_set(err, "mass-spring: no nodes");
  ms->n = n;
  ms->cap = n;
  ms->p = *p;
  ms->damping_scale = 1;
  ms->x = calloc(3 * n, sizeof(double));
  ms->v = calloc(3 * n, sizeof(double));
  ms->x_rest = calloc(3 * n, sizeof(double));
  ms->f_ext = calloc(3 * n, sizeof(double));
  ms->inv_mass = calloc(n, sizeof(double));
  ms->mass = calloc(n, sizeof(double));
  if (!ms->x || !ms->v || !ms->x_rest || !ms->f_ext || !ms->inv_mass || !ms->mass) {
    mass_spring_destroy(ms);
    return verr_set(err, "mass-spring: out of memory for %zu nodes", n);
  }
  memcpy(ms->x, pos, 3 * n * sizeof(double));
  memcpy(ms->x_rest, pos, 3 * n * sizeof(double));
  for (size_t i = 0; i < n; i++) {
    ms->mass[i] = p->mass / (double)n;
    ms->inv_mass[i] = 1.0 / ms->mass[i];
  }
  ms->fs = (force_system_t){.n = n,
                            .x = ms->x,
                            .v = ms->v,
                            .mass = ms->mass,
                            .inv_mass = ms->inv_mass,
                            .forces = fs_forces,
                            .stiffness_mul = fs_stiffness_mul};
  return 0;
}

/* Edge set: sort (min, max) pairs and drop repeats. O(E log E), no hash
 * table needed for a one-off build. */
static int cmp_edge(const void *a, const void *b) {
  const uint32_t *x = a, *y = b;
  if (x[0] != y[0]) return x[0] < y[0] ? -1 : 1;
  return (x[1] > y[1]) - (x[1] < y[1]);
}

/* Takes ownership of `edges` (ne raw (i, j) pairs, normalised i < j here).
 * On OOM the old springs are kept and -1 returned. */
static int ms_make_springs(mass_spring_t *ms, uint32_t *edges, size_t ne, verr_t *err) {
  for (size_t e = 0; e < ne; e++) {
    uint32_t i = edges[2 * e], j = edges[2 * e + 1];
    if (i > j) {
      edges[2 * e] = j;
      edges[2 * e + 1] = i;
    }
  }
  qsort(edges, ne, 2 * sizeof(uint32_t), cmp_edge);
  size_t unique = 0;
  for (size_t e = 0; e < ne; e++)
    if (e == 0 || cmp_edge(edges + 2 * e, edges + 2 * (e - 1)) != 0) unique++;
  ms_spring_t *springs = malloc((unique + 1) * sizeof(ms_spring_t));
  if (!springs) {
    free(edges);
    return verr_set(err, "mass-spring: out of memory for %zu springs", unique);
  }
  free(ms->springs);
  ms->springs = springs;
  ms->nsprings = 0;
  for (size_t e = 0; e < ne; e++) {
    if (e > 0 && cmp_edge(edges + 2 * e, edges + 2 * (e - 1)) == 0) continue;
    uint32_t i = edges[2 * e], j = edges[2 * e + 1];
    if (i == j) continue; /* a degenerate element's collapsed edge */
    ms_spring_t *sp = &ms->springs[ms->nsprings++];
    sp->i = i;
    sp->j = j;
    sp->rest = v3_dist(ms->x_rest + 3 * i, ms->x_rest + 3 * j);
  }
  free(edges);
  mass_spring_springs_changed(ms);
  return 0;
}

static int ms_build_springs(mass_spring_t *ms, uint32_t *edges, size_t ne, verr_t *err) {
  if (ms_make_springs(ms, edges, ne, err)) {
    mass_spring_destroy(ms);
    return -1;
  }
  return 0;
}

/* realloc that keeps *p on failure. */
static int grow(double **p, size_t count) {
  double *q = realloc(*p, count * sizeof(double) + 1);
  if (!q) return -1;
  *p = q;
  return 0;
}

int mass_spring_reserve(mass_spring_t *ms, size_t cap, int with_f_res, verr_t *err) {
  if (cap > ((size_t)-1) / (3 * sizeof(double)) - 1) return verr_set(err, "mass-spring: %zu nodes is too many", cap);
  if (cap > ms->cap) {
    if (grow(&ms->x, 3 * cap) || grow(&ms->v, 3 * cap) || grow(&ms->x_rest, 3 * cap) || grow(&ms->f_ext, 3 * cap) ||
        grow(&ms->mass, cap) || grow(&ms->inv_mass, cap) || (ms->f_res && grow(&ms->f_res, 3 * cap)))
      return verr_set(err, "mass-spring: out of memory for %zu nodes", cap);
    /* f_ext is all zero between steps (the model clears it); keep that. */
    memset(ms->f_ext + 3 * ms->n, 0, 3 * (cap - ms->n) * sizeof(double));
    if (ms->f_res) memset(ms->f_res + 3 * ms->n, 0, 3 * (cap - ms->n) * sizeof(double));
    ms->cap = cap;
  }
  if (with_f_res && !ms->f_res) {
    ms->f_res = calloc(3 * ms->cap + 1, sizeof(double));
    if (!ms->f_res) return verr_set(err, "mass-spring: out of memory for residual forces");
  }
  ms->fs.x = ms->x;
  ms->fs.v = ms->v;
  ms->fs.mass = ms->mass;
  ms->fs.inv_mass = ms->inv_mass;
  return 0;
}

int mass_spring_set_surface_topology(mass_spring_t *ms, size_t n, const uint32_t *tris, size_t ntris, verr_t *err) {
  if (n == 0 || n > ms->cap) return verr_set(err, "mass-spring: %zu nodes (capacity %zu)", n, ms->cap);
  for (size_t c = 0; c < 3 * ntris; c++)
    if (tris[c] >= n) return verr_set(err, "mass-spring: triangle %zu has a vertex index out of range", c / 3);
  uint32_t *edges = malloc(ntris * 6 * sizeof(uint32_t) + 1);
  if (!edges) return verr_set(err, "mass-spring: out of memory for edges");
  for (size_t t = 0; t < ntris; t++)
    for (int k = 0; k < 3; k++) {
      edges[6 * t + 2 * k] = tris[3 * t + k];
      edges[6 * t + 2 * k + 1] = tris[3 * t + (k + 1) % 3];
    }
  if (ms_make_springs(ms, edges, 3 * ntris, err)) return -1;
  /* Per-spring stiffness factors were indexed by the old springs: a cut
   * renumbers them, so the mesh goes back to uniform stiffness. */
  free(ms->k_scale);
  ms->k_scale = NULL;
  ms->n = n;
  ms->fs.n = n;
  double total = 0;
  for (size_t i = 0; i < n; i++) total += ms->mass[i];
  ms->p.mass = total;
  return 0;
}

int mass_spring_create_surface(mass_spring_t *ms, const mesh_t *s, const ms_params_t *p, verr_t *err) {
  if (ms_alloc(ms, s->nverts, s->pos, p, err)) return -1;
  double total_area = 0;
  for (size_t t = 0; t < s->ntris; t++) {
    const uint32_t *f = s->tris + 3 * t;
    if (f[0] >= s->nverts || f[1] >= s->nverts || f[2] >= s->nverts) {
      mass_spring_destroy(ms);
      return verr_set(err, "mass-spring: triangle %zu has a vertex index out of range", t);
    }
    double e1[3], e2[3], c[3];
    v3_sub(e1, s->pos + 3 * f[1], s->pos + 3 * f[0]);
    v3_sub(e2, s->pos + 3 * f[2], s->pos + 3 * f[0]);
    v3_cross(c, e1, e2);
    total_area += 0.5 * v3_norm(c);
  }
  if (!(total_area > 0)) {
    mass_spring_destroy(ms);
    return verr_set(err, "mass-spring: mesh has zero surface area");
  }
  uint32_t *edges = malloc(s->ntris * 6 * sizeof(uint32_t) + 1);
  if (!edges) {
    mass_spring_destroy(ms);
    return verr_set(err, "mass-spring: out of memory for edges");
  }
  for (size_t t = 0; t < s->ntris; t++)
    for (int k = 0; k < 3; k++) {
      edges[6 * t + 2 * k] = s->tris[3 * t + k];
      edges[6 * t + 2 * k + 1] = s->tris[3 * t + (k + 1) % 3];
    }
  return ms_build_springs(ms, edges, 3 * s->ntris, err);
}

int mass_spring_create_tets(mass_spring_t *ms, const tet_mesh_t *t, const ms_params_t *p, verr_t *err) {
  if (t->ntets == 0) return verr_set(err, "mass-spring: the tetrahedral mesh has no tetrahedra");
  if (ms_alloc(ms, t->nnodes, t->x, p, err)) return -1;
  static const int E[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  uint32_t *edges = malloc(t->ntets * 12 * sizeof(uint32_t) + 1);
  if (!edges) {
    mass_spring_destroy(ms);
    return verr_set(err, "mass-spring: out of memory for edges");
  }
  for (size_t e = 0; e < t->ntets; e++) {
    const uint32_t *q = t->tets + 4 * e;
    for (int k = 0; k < 4; k++)
      if (q[k] >= t->nnodes) {
        free(edges);
        mass_spring_destroy(ms);
        return verr_set(err, "mass-spring: tetrahedron %zu has a node index out of range", e);
      }
    for (int k = 0; k < 6; k++) {
      edges[12 * e + 2 * k] = q[E[k][0]];
      edges[12 * e + 2 * k + 1] = q[E[k][1]];
    }
  }
  return ms_build_springs(ms, edges, 6 * t->ntets, err);
}

void mass_spring_destroy(mass_spring_t *ms) {
  free(ms->x);
  free(ms->v);
  free(ms->x_rest);
  free(ms->f_ext);
  free(ms->inv_mass);
  free(ms->mass);
  free(ms->springs);
  free(ms->k_scale);
  free(ms->f_res);
  free(ms->gather.off);
  free(ms->gather.ev);
  free(ms->gather.g);
  memset(ms, 0, sizeof *ms);
}

size_t mass_spring_fix_below(mass_spring_t *ms, double z) {
  size_t count = 0;
  for (size_t i = 0; i < ms->n; i++)
    if (ms->x_rest[3 * i + 2] < z) {
      ms->inv_mass[i] = 0;
      count++;
    }
  return count;
}

/* The spring loops below are bound by the gathers of x_j, v_j and the
 * scatters into f_j, not by arithmetic (auto-vectorised variants measured no
 * faster). ms_make_springs sorts springs by (i, j), so consecutive springs
 * usually share node i: each loop walks a run of equal i, keeps x_i, v_i
 * (or y_i) and the accumulated force on i in registers and writes node i
 * once per run. The result is the same force to rounding (only the summation
 * order on node i changes). Any spring order stays correct: an unsorted array
 * just makes shorter runs (down to one spring), which is slower, not wrong.
 * The k_scale test is a compile-time constant of each instantiation (the
 * inline helper is called with scaled = 0 and 1), so the common uniform case
 * carries no branch per spring. */
static inline void ms_spring_forces(const mass_spring_t *ms, const double *restrict x, const double *restrict v,
                                    double *restrict f, int scaled, double damping) {
  const ms_spring_t *restrict sp = ms->springs;
  const double *restrict kscale = ms->k_scale;
  const double stiffness = ms->p.stiffness;
  const size_t ns = ms->nsprings;
  size_t s = 0;
  while (s < ns) {
    const uint32_t i = sp[s].i;
    const double xi0 = x[3 * i], xi1 = x[3 * i + 1], xi2 = x[3 * i + 2];
    const double vi0 = v[3 * i], vi1 = v[3 * i + 1], vi2 = v[3 * i + 2];
    double fi0 = 0, fi1 = 0, fi2 = 0;
    for (; s < ns && sp[s].i == i; s++) {
      const uint32_t j = sp[s].j;
      const double d0 = x[3 * j] - xi0, d1 = x[3 * j + 1] - xi1, d2 = x[3 * j + 2] - xi2;
      const double len = sqrt(d0 * d0 + d1 * d1 + d2 * d2);
      /* A zero-length spring has no direction: it then pushes nothing, which
       * keeps forces finite when two nodes are moved onto each other. */
      if (len <= MS_TINY) continue;
      /* With u = d / len: the damping projection is (dv . d) / len and the
       * force mag u = (mag / len) d, so one reciprocal and no normalised
       * vector are needed. */
      const double inv = 1.0 / len;
      const double dvd = (v[3 * j] - vi0) * d0 + (v[3 * j + 1] - vi1) * d1 + (v[3 * j + 2] - vi2) * d2;
      const double k = scaled ? stiffness * kscale[s] : stiffness;
      const double mag = (k * (len - sp[s].rest) + damping * dvd * inv) * inv;
      const double g0 = mag * d0, g1 = mag * d1, g2 = mag * d2;
      fi0 += g0;
      fi1 += g1;
      fi2 += g2;
      f[3 * j] -= g0;
      f[3 * j + 1] -= g1;
      f[3 * j + 2] -= g2;
    }
    f[3 * i] += fi0;
    f[3 * i + 1] += fi1;
    f[3 * i + 2] += fi2;
  }
}

#ifdef VISCERA_HAVE_AVX_ROWS
#define MS_HAVE_AVX2_PATH 1

/* The spring loop with the arithmetic four springs at a time (AVX2, chosen
 * at run time): both ends' x and v as masked row loads transposed into one
 * vector per component (the hardware gathers measured slower), then the
 * difference, length (one 4-wide square root and divide instead of four
 * scalar ones), damping projection and force g of each spring, with
 * exactly the scalar loop's operations in its order (mul and add, no fused
 * multiply-add), then the scatter of the four g in spring order with the
 * same runs of equal i as the scalar loop: the forces are bit for bit the
 * scalar path's (test_ms_forces). */

/* Springs sp[0..3]: their direction d (j - i, unnormalised, one vector per
 * component), which of them are live (longer than MS_TINY; a zero-length
 * spring pushes nothing, NaN stays live, as in the scalar test) and the force
 * magnitude per unit of d, (k (len - rest) + c (dv . d) / len) / len: the
 * scalar loop's operations in its order, 4 lanes at once. Shared by the
 * scatter and the gather loop, so both stay bit-identical to the scalar one.
 * kscale: the 4 springs' stiffness factors, or NULL. */
__attribute__((target("avx2"))) static inline __m256d spring4(const ms_spring_t *restrict sp, const double *restrict x,
                                                              const double *restrict v, const double *restrict kscale,
                                                              __m256d stiff, __m256d damp, __m256d *d0, __m256d *d1,
                                                              __m256d *d2, __m256d *live) {
  const __m256i m3 = _mm256_set_epi64x(0, -1, -1, -1);
  const __m256d one = _mm256_set1_pd(1.0), tiny = _mm256_set1_pd(MS_TINY);
  /* Each end's (x, y, z) as one masked 4-wide load (the fourth lane is not
   * read: no access past the array), the differences row by row, then a 4x4
   * transpose into one vector per component. */
  __m256d dr[4], dvr[4];
  for (int q = 0; q < 4; q++) {
    const size_t i3 = 3 * (size_t)sp[q].i, j3 = 3 * (size_t)sp[q].j;
    dr[q] = _mm256_sub_pd(_mm256_maskload_pd(x + j3, m3), _mm256_maskload_pd(x + i3, m3));
    dvr[q] = _mm256_sub_pd(_mm256_maskload_pd(v + j3, m3), _mm256_maskload_pd(v + i3, m3));
  }
  __m256d dv0, dv1, dv2;
  avx_rows_transpose3(dr, d0, d1, d2);
  avx_rows_transpose3(dvr, &dv0, &dv1, &dv2);
  const __m256d len = _mm256_sqrt_pd(
      _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(*d0, *d0), _mm256_mul_pd(*d1, *d1)), _mm256_mul_pd(*d2, *d2)));
  *live = _mm256_cmp_pd(len, tiny, _CMP_NLE_UQ);
  const __m256d inv = _mm256_div_pd(one, len);
  const __m256d dvd =
      _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dv0, *d0), _mm256_mul_pd(dv1, *d1)), _mm256_mul_pd(dv2, *d2));
  const __m256d rest = _mm256_set_pd(sp[3].rest, sp[2].rest, sp[1].rest, sp[0].rest);
  const __m256d k = kscale ? _mm256_mul_pd(stiff, _mm256_loadu_pd(kscale)) : stiff;
  return _mm256_and_pd(*live, _mm256_mul_pd(_mm256_add_pd(_mm256_mul_pd(k, _mm256_sub_pd(len, rest)),
                                                          _mm256_mul_pd(_mm256_mul_pd(damp, dvd), inv)),
                                            inv));
}

__attribute__((target("avx2"))) static void ms_spring_forces_avx2(const mass_spring_t *ms, const double *restrict x,
                                                                  const double *restrict v, double *restrict f,
                                                                  double damping) {
  const ms_spring_t *restrict sp = ms->springs;
  const double *restrict kscale = ms->k_scale;
  const size_t ns = ms->nsprings;
  const __m256d stiff = _mm256_set1_pd(ms->p.stiffness), damp = _mm256_set1_pd(damping);
  uint32_t cur = UINT32_MAX;
  double fi0 = 0, fi1 = 0, fi2 = 0;
  size_t s = 0;
  for (; s + 4 <= ns; s += 4) {
    __m256d d0, d1, d2, live;
    const __m256d mag = spring4(sp + s, x, v, kscale ? kscale + s : NULL, stiff, damp, &d0, &d1, &d2, &live);
    double g[3][4];
    _mm256_storeu_pd(g[0], _mm256_mul_pd(mag, d0));
    _mm256_storeu_pd(g[1], _mm256_mul_pd(mag, d1));
    _mm256_storeu_pd(g[2], _mm256_mul_pd(mag, d2));
    const int lv = _mm256_movemask_pd(live);
    for (int q = 0; q < 4; q++) {
      const uint32_t i = sp[s + q].i, j = sp[s + q].j;
      if (i != cur) {
        if (cur != UINT32_MAX) {
          f[3 * (size_t)cur] += fi0;
          f[3 * (size_t)cur + 1] += fi1;
          f[3 * (size_t)cur + 2] += fi2;
        }
        cur = i;
        fi0 = fi1 = fi2 = 0;
      }
      if (!((lv >> q) & 1)) continue; /* as the scalar loop: skipped, not added as 0 */
      fi0 += g[0][q];
      fi1 += g[1][q];
      fi2 += g[2][q];
      f[3 * (size_t)j] -= g[0][q];
      f[3 * (size_t)j + 1] -= g[1][q];
      f[3 * (size_t)j + 2] -= g[2][q];
    }
  }
  /* The remainder (fewer than four springs), scalar, continuing the run. */
  for (; s < ns; s++) {
    const uint32_t i = sp[s].i, j = sp[s].j;
    if (i != cur) {
      if (cur != UINT32_MAX) {
        f[3 * (size_t)cur] += fi0;
        f[3 * (size_t)cur + 1] += fi1;
        f[3 * (size_t)cur + 2] += fi2;
      }
      cur = i;
      fi0 = fi1 = fi2 = 0;
    }
    const double *xi = x + 3 * (size_t)i, *xj = x + 3 * (size_t)j, *vi = v + 3 * (size_t)i, *vj = v + 3 * (size_t)j;
    const double d0 = xj[0] - xi[0], d1 = xj[1] - xi[1], d2 = xj[2] - xi[2];
    const double len = sqrt(d0 * d0 + d1 * d1 + d2 * d2);
    if (len <= MS_TINY) continue;
    const double inv = 1.0 / len;
    const double dvd = (vj[0] - vi[0]) * d0 + (vj[1] - vi[1]) * d1 + (vj[2] - vi[2]) * d2;
    const double k = kscale ? ms->p.stiffness * kscale[s] : ms->p.stiffness;
    const double mag = (k * (len - sp[s].rest) + damping * dvd * inv) * inv;
    fi0 += mag * d0;
    fi1 += mag * d1;
    fi2 += mag * d2;
    f[3 * (size_t)j] -= mag * d0;
    f[3 * (size_t)j + 1] -= mag * d1;
    f[3 * (size_t)j + 2] -= mag * d2;
  }
  if (cur != UINT32_MAX) {
    f[3 * (size_t)cur] += fi0;
    f[3 * (size_t)cur + 1] += fi1;
    f[3 * (size_t)cur + 2] += fi2;
  }
}
#endif

/* The gather form of the AVX2 loop. The scatter loop above spends most
 * of its time in the scalar read-modify-write of f_j after the 4-wide
 * arithmetic. Here pass 1 computes every spring's force g (the same
 * vector arithmetic) and stores it as one row (g0, g1, g2, live) per
 * spring, in spring order: contiguous stores, no scatter. Pass 2 walks the
 * nodes in order, computes the node terms, and gathers each node's springs
 * from the gather index: its events in the order the scalar loop applies
 * them (f_j -= g at spring s; a run of springs with i = this node summed
 * from zero, then added, at the run's end), one 4-wide load and subtract
 * or add per event. Same operations in the same order per component, so
 * the forces are the scalar loop's bit for bit (test_ms_forces). */
#define MS_RUN 0x80000000u

void mass_spring_springs_changed(mass_spring_t *ms) {
  struct ms_gather *g = &ms->gather;
  free(g->off);
  free(g->ev);
  free(g->g);
  memset(g, 0, sizeof *g);
  const ms_spring_t *sp = ms->springs;
  size_t ns = ms->nsprings, nv = 0, nruns = 0;
  if (!sp || !ns || ns >= MS_RUN) return;
  for (size_t s = 0; s < ns; s++) {
    nv = sp[s].i >= nv ? (size_t)sp[s].i + 1 : nv;
    nv = sp[s].j >= nv ? (size_t)sp[s].j + 1 : nv;
    nruns += s == 0 || sp[s].i != sp[s - 1].i;
  }
  g->off = calloc(nv + 2, sizeof *g->off);
  g->ev = malloc((ns + 2 * nruns) * sizeof *g->ev);
  g->g = aligned_alloc(32, 4 * ns * sizeof *g->g);
  if (!g->off || !g->ev || !g->g) {
    free(g->off);
    free(g->ev);
    free(g->g);
    memset(g, 0, sizeof *g);
    return;
  }
  /* Counts at off[k + 2], prefix sums make off[k + 1] node k's start,
   * which then serves as its cursor: filled, off[k] is node k's start.
   * Filled in the scalar loop's order: a run's event when the run ends
   * (before the next spring's f_j), a spring's f_j at the spring. */
  for (size_t s = 0; s < ns; s++) {
    g->off[sp[s].j + 2]++;
    if (s == 0 || sp[s].i != sp[s - 1].i) g->off[sp[s].i + 2] += 2;
  }
  for (size_t k = 2; k < nv + 2; k++) g->off[k] += g->off[k - 1];
  size_t rb = 0;
  for (size_t s = 0; s <= ns; s++) {
    if (s > 0 && (s == ns || sp[s].i != sp[s - 1].i)) {
      uint32_t k = sp[s - 1].i;
      g->ev[g->off[k + 1]++] = MS_RUN | (uint32_t)rb;
      g->ev[g->off[k + 1]++] = (uint32_t)s;
      rb = s;
    }
    if (s < ns) g->ev[g->off[sp[s].j + 1]++] = (uint32_t)s;
  }
  g->springs = sp;
  g->nsprings = ns;
  g->nv = nv;
}

#ifdef MS_HAVE_AVX2_PATH
/* Pass 1 for the springs 4b .. 4b + 3 (a whole block: s + 4 <= ns): g rows;
 * returns how many are dead (zero length: live lane +0.0, else -0.0, whose
 * sign bit pass 2 can blend on). */
__attribute__((target("avx2"))) static inline size_t ms_row_block(const ms_spring_t *restrict sp,
                                                                  const double *restrict x, const double *restrict v,
                                                                  const double *restrict kscale, double *restrict g,
                                                                  size_t s, __m256d stiff, __m256d damp) {
  const __m256d nzero = _mm256_set1_pd(-0.0);
  __m256d d0, d1, d2, live;
  const __m256d mag = spring4(sp + s, x, v, kscale ? kscale + s : NULL, stiff, damp, &d0, &d1, &d2, &live);
  const __m256d c0 = _mm256_mul_pd(mag, d0), c1 = _mm256_mul_pd(mag, d1), c2 = _mm256_mul_pd(mag, d2);
  const __m256d c3 = _mm256_and_pd(live, nzero);
  /* Columns back to one row per spring. */
  const __m256d t0 = _mm256_unpacklo_pd(c0, c1), t1 = _mm256_unpackhi_pd(c0, c1);
  const __m256d t2 = _mm256_unpacklo_pd(c2, c3), t3 = _mm256_unpackhi_pd(c2, c3);
  _mm256_store_pd(g + 4 * s, _mm256_permute2f128_pd(t0, t2, 0x20));
  _mm256_store_pd(g + 4 * s + 4, _mm256_permute2f128_pd(t1, t3, 0x20));
  _mm256_store_pd(g + 4 * s + 8, _mm256_permute2f128_pd(t0, t2, 0x31));
  _mm256_store_pd(g + 4 * s + 12, _mm256_permute2f128_pd(t1, t3, 0x31));
  return 4 - (size_t)__builtin_popcount((unsigned)_mm256_movemask_pd(live));
}

/* Pass 1 for the springs s .. ns - 1 (fewer than four), scalar: the same
 * operations. Returns how many are dead. */
static size_t ms_row_tail(const mass_spring_t *ms, const double *restrict x, const double *restrict v,
                          double *restrict g, size_t s, double damping) {
  const ms_spring_t *restrict sp = ms->springs;
  const double *restrict kscale = ms->k_scale;
  size_t dead = 0;
  for (; s < ms->nsprings; s++) {
    const double *xi = x + 3 * (size_t)sp[s].i, *xj = x + 3 * (size_t)sp[s].j;
    const double *vi = v + 3 * (size_t)sp[s].i, *vj = v + 3 * (size_t)sp[s].j;
    const double d0 = xj[0] - xi[0], d1 = xj[1] - xi[1], d2 = xj[2] - xi[2];
    const double len = sqrt(d0 * d0 + d1 * d1 + d2 * d2);
    double *row = g + 4 * s;
    if (len <= MS_TINY) {
      row[0] = row[1] = row[2] = row[3] = 0;
      dead++;
      continue;
    }
    const double inv = 1.0 / len;
    const double dvd = (vj[0] - vi[0]) * d0 + (vj[1] - vi[1]) * d1 + (vj[2] - vi[2]) * d2;
    const double k = kscale ? ms->p.stiffness * kscale[s] : ms->p.stiffness;
    const double mag = (k * (len - sp[s].rest) + damping * dvd * inv) * inv;
    row[0] = mag * d0;
    row[1] = mag * d1;
    row[2] = mag * d2;
    row[3] = -0.0;
  }
  return dead;
}

/* Pass 1: g rows of every spring; returns how many are dead. */
__attribute__((target("avx2"))) static size_t ms_gather_rows(const mass_spring_t *ms, const double *restrict x,
                                                             const double *restrict v, double *restrict g,
                                                             double damping) {
  const ms_spring_t *restrict sp = ms->springs;
  const double *restrict kscale = ms->k_scale;
  const size_t ns = ms->nsprings;
  const __m256d stiff = _mm256_set1_pd(ms->p.stiffness), damp = _mm256_set1_pd(damping);
  size_t s = 0, dead = 0;
  for (; s + 4 <= ns; s += 4) dead += ms_row_block(sp, x, v, kscale, g, s, stiff, damp);
  return dead + ms_row_tail(ms, x, v, g, s, damping);
}

/* Pass 2 for node k: node terms, then its events (see above). `blend`:
 * some spring may be dead and must be skipped, as the scalar loop skips it
 * (blending is exact for live springs too, only slower). */
typedef struct ms_node_consts {
  __m256i m3;
  __m256d grav, hk, hc;
} ms_node_consts_t;

__attribute__((target("avx2"))) static inline ms_node_consts_t ms_node_consts(const mass_spring_t *ms) {
  return (ms_node_consts_t){.m3 = _mm256_set_epi64x(0, -1, -1, -1),
                            .grav = _mm256_set_pd(0, ms->p.gravity[2], ms->p.gravity[1], ms->p.gravity[0]),
                            .hk = _mm256_set1_pd(ms->p.home_stiffness),
                            .hc = _mm256_set1_pd(ms->p.home_damping)};
}

__attribute__((target("avx2"))) static inline void ms_gather_node(const mass_spring_t *ms, const ms_node_consts_t *kc,
                                                                  const double *restrict x, const double *restrict v,
                                                                  double *restrict f, const double *restrict g,
                                                                  int blend, size_t k) {
  const struct ms_gather *gi = &ms->gather;
  const uint32_t *restrict off = gi->off, *restrict ev = gi->ev;
  const double *restrict xr = ms->x_rest, *restrict fext = ms->f_ext, *restrict mass = ms->mass;
  const double *restrict fres = ms->f_res;
  const __m256i m3 = kc->m3;
  const size_t c = 3 * k;
  __m256d acc = _mm256_add_pd(_mm256_maskload_pd(fext + c, m3), _mm256_mul_pd(_mm256_set1_pd(mass[k]), kc->grav));
  acc = _mm256_sub_pd(
      acc, _mm256_mul_pd(kc->hk, _mm256_sub_pd(_mm256_maskload_pd(x + c, m3), _mm256_maskload_pd(xr + c, m3))));
  acc = _mm256_sub_pd(acc, _mm256_mul_pd(kc->hc, _mm256_maskload_pd(v + c, m3)));
  if (fres) acc = _mm256_add_pd(acc, _mm256_maskload_pd(fres + c, m3));
  if (k < gi->nv) {
    const uint32_t *e = ev + off[k], *end = ev + off[k + 1];
    while (e < end) {
      const uint32_t q = *e++;
      if (q & MS_RUN) {
        const uint32_t re = *e++;
        __m256d r = _mm256_setzero_pd();
        for (uint32_t s = q & ~MS_RUN; s < re; s++) {
          const __m256d gs = _mm256_load_pd(g + 4 * (size_t)s);
          r = blend ? _mm256_blendv_pd(r, _mm256_add_pd(r, gs), _mm256_permute4x64_pd(gs, 0xff)) : _mm256_add_pd(r, gs);
        }
        acc = _mm256_add_pd(acc, r);
      } else {
        const __m256d gs = _mm256_load_pd(g + 4 * (size_t)q);
        acc = blend ? _mm256_blendv_pd(acc, _mm256_sub_pd(acc, gs), _mm256_permute4x64_pd(gs, 0xff))
                    : _mm256_sub_pd(acc, gs);
      }
    }
  }
  _mm256_maskstore_pd(f + c, m3, acc);
}

/* Pass 2 over every node. */
__attribute__((target("avx2"))) static void ms_gather_nodes(const mass_spring_t *ms, const double *restrict x,
                                                            const double *restrict v, double *restrict f,
                                                            const double *restrict g, int blend) {
  const ms_node_consts_t kc = ms_node_consts(ms);
  const size_t n = ms->n;
  if (blend)
    for (size_t k = 0; k < n; k++) ms_gather_node(ms, &kc, x, v, f, g, 1, k);
  else
    for (size_t k = 0; k < n; k++) ms_gather_node(ms, &kc, x, v, f, g, 0, k);
}

/* The active set (mass_spring_forces_subset): pass 1 over the marked
 * blocks, pass 2 over the marked nodes. Blending always: rows of blocks not
 * evaluated now may be dead ones from before. */
__attribute__((target("avx2"))) static void ms_gather_subset(const mass_spring_t *ms, const double *restrict x,
                                                             const double *restrict v, double *restrict f,
                                                             const uint64_t *blk, const uint64_t *nodes,
                                                             double damping) {
  const ms_spring_t *restrict sp = ms->springs;
  const double *restrict kscale = ms->k_scale;
  double *restrict g = ms->gather.g;
  const size_t ns = ms->nsprings, nb = (ns + 3) / 4;
  const __m256d stiff = _mm256_set1_pd(ms->p.stiffness), damp = _mm256_set1_pd(damping);
  for (size_t w = 0; w < (nb + 63) / 64; w++)
    for (uint64_t bits = blk[w]; bits; bits &= bits - 1) {
      const size_t s = 4 * (64 * w + (size_t)__builtin_ctzll(bits));
      if (s + 4 <= ns)
        ms_row_block(sp, x, v, kscale, g, s, stiff, damp);
      else if (s < ns)
        ms_row_tail(ms, x, v, g, s, damping);
    }
  const ms_node_consts_t kc = ms_node_consts(ms);
  const size_t n = ms->n;
  for (size_t w = 0; w < (n + 63) / 64; w++)
    for (uint64_t bits = nodes[w]; bits; bits &= bits - 1) {
      const size_t k = 64 * w + (size_t)__builtin_ctzll(bits);
      if (k < n) ms_gather_node(ms, &kc, x, v, f, g, 1, k);
    }
}
#endif
#undef MS_RUN

/* The gather index matches the springs (and nodes) it was built for. */
static int ms_gather_usable(const mass_spring_t *ms) {
  const struct ms_gather *g = &ms->gather;
  return g->g && g->springs == ms->springs && g->nsprings == ms->nsprings && g->nv <= ms->n;
}

int mass_spring_simd_available(void) {
#ifdef MS_HAVE_AVX2_PATH
  return __builtin_cpu_supports("avx2") ? 1 : 0;
#else
  return 0;
#endif
}

int mass_spring_subset_available(const mass_spring_t *ms) {
#ifdef MS_HAVE_AVX2_PATH
  return ms_gather_usable(ms) && mass_spring_simd_available();
#else
  (void)ms;
  return 0;
#endif
}

void mass_spring_forces_subset(const mass_spring_t *ms, const double *x, const double *v, double *f,
                               const uint64_t *blk, const uint64_t *nodes) {
#ifdef MS_HAVE_AVX2_PATH
  if (mass_spring_subset_available(ms)) {
    ms_gather_subset(ms, x, v, f, blk, nodes, ms->p.damping * ms->damping_scale);
    return;
  }
#endif
  (void)blk;
  (void)nodes;
  mass_spring_forces(ms, x, v, f);
}

void mass_spring_forces(const mass_spring_t *ms, const double *x, const double *v, double *f) {
  mass_spring_forces_path(ms, x, v, f, mass_spring_simd_available());
}

void mass_spring_forces_path(const mass_spring_t *ms, const double *x, const double *v, double *f, int simd) {
  const double damping = ms->p.damping * ms->damping_scale; /* mass_spring.h: damping_scale */
#ifdef MS_HAVE_AVX2_PATH
  if (simd == 1 && ms_gather_usable(ms) && mass_spring_simd_available()) {
    size_t dead = ms_gather_rows(ms, x, v, ms->gather.g, damping);
    ms_gather_nodes(ms, x, v, f, ms->gather.g, dead > 0);
    return;
  }
#endif
  /* Node terms. The parameters are copied to locals and the arrays are
   * restrict-qualified: through plain pointers every store to f could alias
   * ms->p, so the compiler reloaded gravity and the home coefficients per
   * node (this loop took a sixth of the spring loop's time). */
  const double *restrict xr = ms->x_rest, *restrict fext = ms->f_ext, *restrict mass = ms->mass;
  const double *restrict fres = ms->f_res;
  const double *restrict xx = x, *restrict vv = v;
  double *restrict ff = f;
  const double g0 = ms->p.gravity[0], g1 = ms->p.gravity[1], g2 = ms->p.gravity[2];
  const double hk = ms->p.home_stiffness, hc = ms->p.home_damping;
  const size_t n = ms->n;
  for (size_t i = 0; i < n; i++) {
    const size_t c = 3 * i;
    ff[c] = fext[c] + mass[i] * g0 - hk * (xx[c] - xr[c]) - hc * vv[c];
    ff[c + 1] = fext[c + 1] + mass[i] * g1 - hk * (xx[c + 1] - xr[c + 1]) - hc * vv[c + 1];
    ff[c + 2] = fext[c + 2] + mass[i] * g2 - hk * (xx[c + 2] - xr[c + 2]) - hc * vv[c + 2];
  }
  if (fres)
    for (size_t c = 0; c < 3 * n; c++) ff[c] += fres[c];
#ifdef MS_HAVE_AVX2_PATH
  if (simd && mass_spring_simd_available()) {
    ms_spring_forces_avx2(ms, x, v, f, damping);
    return;
  }
#else
  (void)simd;
#endif
  if (ms->k_scale)
    ms_spring_forces(ms, x, v, f, 1, damping);
  else
    ms_spring_forces(ms, x, v, f, 0, damping);
}

/* The Jacobian product, walked by runs of equal i like the forces (above).
 * Per spring: t = axial (u u^T) w + geo (I - u u^T) w with w = y_i - y_j;
 * out_i += t, out_j -= t. */
static inline void ms_spring_stiffness_mul(const mass_spring_t *ms, const double *restrict x, double a, double b,
                                           const double *restrict y, double *restrict out, int scaled) {
  const ms_spring_t *restrict sp = ms->springs;
  const double *restrict kscale = ms->k_scale;
  const double stiffness = ms->p.stiffness, bdamp = b * ms->p.damping;
  const int definite = ms->definite_jacobian;
  const size_t ns = ms->nsprings;
  size_t s = 0;
  while (s < ns) {
    const uint32_t i = sp[s].i;
    const double xi0 = x[3 * i], xi1 = x[3 * i + 1], xi2 = x[3 * i + 2];
    const double yi0 = y[3 * i], yi1 = y[3 * i + 1], yi2 = y[3 * i + 2];
    double ti0 = 0, ti1 = 0, ti2 = 0;
    for (; s < ns && sp[s].i == i; s++) {
      const uint32_t j = sp[s].j;
      const double d0 = x[3 * j] - xi0, d1 = x[3 * j + 1] - xi1, d2 = x[3 * j + 2] - xi2;
      const double len = sqrt(d0 * d0 + d1 * d1 + d2 * d2);
      if (len <= MS_TINY) continue; /* the force is 0 there (see forces) */
      const double inv = 1.0 / len;
      const double u0 = d0 * inv, u1 = d1 * inv, u2 = d2 * inv;
      const double ks = scaled ? stiffness * kscale[s] : stiffness;
      const double axial = a * ks + bdamp;
      double geo = 1 - sp[s].rest * inv;
      if (definite && geo < 0) geo = 0;
      geo *= a * ks;
      const double w0 = yi0 - y[3 * j], w1 = yi1 - y[3 * j + 1], w2 = yi2 - y[3 * j + 2];
      const double wu = w0 * u0 + w1 * u1 + w2 * u2;
      /* axial wu u + geo (w - wu u) = geo w + (axial - geo) wu u */
      const double cu = (axial - geo) * wu;
      const double t0 = geo * w0 + cu * u0, t1 = geo * w1 + cu * u1, t2 = geo * w2 + cu * u2;
      ti0 += t0;
      ti1 += t1;
      ti2 += t2;
      out[3 * j] -= t0;
      out[3 * j + 1] -= t1;
      out[3 * j + 2] -= t2;
    }
    out[3 * i] += ti0;
    out[3 * i + 1] += ti1;
    out[3 * i + 2] += ti2;
  }
}

void mass_spring_stiffness_mul(const mass_spring_t *ms, const double *x, double a, double b, const double *y,
                               double *out) {
  const ms_params_t *p = &ms->p;
  double diag = a * p->home_stiffness + b * p->home_damping;
  for (size_t c = 0; c < 3 * ms->n; c++) out[c] = diag * y[c];
  if (ms->k_scale)
    ms_spring_stiffness_mul(ms, x, a, b, y, out, 1);
  else
    ms_spring_stiffness_mul(ms, x, a, b, y, out, 0);
}

/* y = M^-1 (A x) on the free nodes with A = K or C at rest plus `extra` I;
 * returns x^T A x (the numerator of the Rayleigh quotient). */
static double rest_apply(const mass_spring_t *ms, int damping, double extra, const double *x, double *y) {
  mass_spring_stiffness_mul(ms, ms->x_rest, damping ? 0 : 1, damping ? 1 : 0, x, y);
  double xax = 0;
  for (size_t i = 0; i < ms->n; i++)
    for (int k = 0; k < 3; k++) {
      size_t c = 3 * i + k;
      y[c] = ms->inv_mass[i] == 0 ? 0 : y[c] + extra * x[c];
      xax += x[c] * y[c];
      y[c] *= ms->inv_mass[i];
    }
  return xax;
}

/* Largest eigenvalue of M^-1 A (A symmetric positive semi-definite at rest,
 * M diagonal: real, non-negative eigenvalues). x is the start vector when
 * warm (else a fixed pseudo-random one) and holds the dominant vector after. */
static double lambda_max(const mass_spring_t *ms, int damping, double extra, double *x, double *y, int warm, int max_it,
                         double tol) {
  /* Block Gershgorin: no eigenvalue exceeds it, so it caps the estimate. */
  double per_spring = damping ? ms->p.damping : ms->p.stiffness;
  double home = (damping ? ms->p.home_damping : ms->p.home_stiffness) + extra;
  for (size_t i = 0; i < ms->n; i++) y[i] = home;
  for (size_t s = 0; s < ms->nsprings; s++) {
    if (!(ms->springs[s].rest > 0)) continue;
    double ks = !damping && ms->k_scale ? per_spring * ms->k_scale[s] : per_spring;
    y[ms->springs[s].i] += 2 * ks;
    y[ms->springs[s].j] += 2 * ks;
  }
  double gersh = 0;
  for (size_t i = 0; i < ms->n; i++) gersh = fmax(gersh, y[i] * ms->inv_mass[i]);
  if (!(gersh > 0)) return 0;

  double norm = 0;
  if (warm)
    for (size_t c = 0; c < 3 * ms->n; c++) norm += x[c] * x[c] * (ms->inv_mass[c / 3] > 0);
  if (!(norm > 0) || !isfinite(norm)) {
    unsigned seed = 12345;
    for (size_t c = 0; c < 3 * ms->n; c++) {
      seed = seed * 1664525u + 1013904223u;
      x[c] = ((double)(seed >> 8) / 16777216.0 - 0.5) * (ms->inv_mass[c / 3] > 0);
    }
  } else
    for (size_t c = 0; c < 3 * ms->n; c++) x[c] *= ms->inv_mass[c / 3] > 0;
  double lambda = 0;
  for (int it = 0; it < max_it; it++) {
    double xmx = 0; /* x^T M x */
    for (size_t c = 0; c < 3 * ms->n; c++) xmx += ms->mass[c / 3] * x[c] * x[c] * (ms->inv_mass[c / 3] > 0);
    if (!(xmx > 0)) return 0;
    double next = rest_apply(ms, damping, extra, x, y) / xmx;
    double ny = 0;
    for (size_t c = 0; c < 3 * ms->n; c++) ny += y[c] * y[c];
    ny = sqrt(ny);
    if (!(ny > 0)) return 0;
    for (size_t c = 0; c < 3 * ms->n; c++) x[c] = y[c] / ny;
    if (it > 20 && fabs(next - lambda) <= tol * next) {
      lambda = next;
      break;
    }
    lambda = next;
  }
  return fmin(1.02 * lambda, gersh);
}

int mass_spring_eigen_bounds(const mass_spring_t *ms, double extra_home_k, double *lambda_k, double *lambda_c) {
  size_t len = 3 * ms->n + 1;
  double *x = malloc(len * sizeof(double)), *y = malloc(len * sizeof(double));
  if (!x || !y) {
    free(x);
    free(y);
    return -1;
  }
  *lambda_k = lambda_max(ms, 0, extra_home_k, x, y, 0, 500, 1e-7);
  *lambda_c = lambda_max(ms, 1, 0, x, y, 0, 500, 1e-7);
  free(x);
  free(y);
  return 0;
}

int mass_spring_eigen_bounds_warm(const mass_spring_t *ms, double extra_home_k, double *vk, double *vc, int warm,
                                  double *lambda_k, double *lambda_c) {
  double *y = malloc((3 * ms->n + 1) * sizeof(double));
  if (!y) return -1;
  /* Warm: the Rayleigh quotient starts inside the top cluster, so a looser
   * stop (1e-5 between iterations) is well inside the 2 % margin. */
  *lambda_k = lambda_max(ms, 0, extra_home_k, vk, y, warm, 500, warm ? 1e-5 : 1e-7);
  /* At rest K = k A + (h + extra) I and C = c A + h_c I share A (the sum of
   * u u^T over springs: the geometric term vanishes at rest), so with equal
   * masses they share the dominant vector and lambda_c follows from
   * lambda_k without a second iteration. */
  *lambda_c = mass_spring_lambda_c_from_k(ms, extra_home_k, *lambda_k);
  if (!isfinite(*lambda_c)) *lambda_c = lambda_max(ms, 1, 0, vc, y, warm, 500, warm ? 1e-5 : 1e-7);
  free(y);
  return 0;
}

int mass_spring_power_steps(const mass_spring_t *ms, double extra_home_k, double *x, double *y, int iterations,
                            int *count, double *lambda) {
  for (int k = 0; k < iterations; k++) {
    double xmx = 0;
    for (size_t c = 0; c < 3 * ms->n; c++) {
      x[c] *= ms->inv_mass[c / 3] > 0;
      xmx += ms->mass[c / 3] * x[c] * x[c];
    }
    if (!(xmx > 0)) return 1;
    double next = rest_apply(ms, 0, extra_home_k, x, y) / xmx, ny = 0;
    for (size_t c = 0; c < 3 * ms->n; c++) ny += y[c] * y[c];
    ny = sqrt(ny);
    if (!(ny > 0)) return 1;
    for (size_t c = 0; c < 3 * ms->n; c++) x[c] = y[c] / ny;
    int done = ++*count > 21 && fabs(next - *lambda) <= 1e-5 * next;
    *lambda = next;
    if (done || *count >= 500) return 1;
  }
  return 0;
}

double mass_spring_gershgorin(const mass_spring_t *ms, double extra_home_k, size_t first_new, double *scratch) {
  /* first_new < n: only springs touching a node >= first_new, and only those
   * nodes' home springs (the part B of a topology change). */
  int part = first_new < ms->n;
  for (size_t i = 0; i < ms->n; i++) scratch[i] = !part || i >= first_new ? ms->p.home_stiffness + extra_home_k : 0;
  for (size_t s = 0; s < ms->nsprings; s++) {
    const ms_spring_t *sp = &ms->springs[s];
    if (!(sp->rest > 0) || (part && sp->i < first_new && sp->j < first_new)) continue;
    scratch[sp->i] += 2 * ms->p.stiffness;
    scratch[sp->j] += 2 * ms->p.stiffness;
  }
  double g = 0;
  for (size_t i = 0; i < ms->n; i++) g = fmax(g, scratch[i] * ms->inv_mass[i]);
  return g;
}

double mass_spring_lambda_c_from_k(const mass_spring_t *ms, double extra_home_k, double lambda_k) {
  double m0 = 0;
  for (size_t i = 0; i < ms->n; i++) {
    if (ms->inv_mass[i] == 0) continue;
    if (m0 == 0) m0 = ms->mass[i];
    if (ms->mass[i] != m0) return NAN;
  }
  if (!(m0 > 0) || !(ms->p.stiffness > 0)) return NAN;
  double a = (lambda_k - (ms->p.home_stiffness + extra_home_k) / m0) / ms->p.stiffness;
  return ms->p.damping * fmax(a, 0) + ms->p.home_damping / m0;
}

double mass_spring_potential(const mass_spring_t *ms, const double *x) {
  double e = 0;
  for (size_t i = 0; i < ms->n; i++) {
    double d[3];
    v3_sub(d, x + 3 * i, ms->x_rest + 3 * i);
    e += 0.5 * ms->p.home_stiffness * v3_dot(d, d);
    e -= ms->mass[i] * v3_dot(ms->p.gravity, x + 3 * i);
    if (ms->f_res) e -= v3_dot(ms->f_res + 3 * i, x + 3 * i);
  }
  for (size_t s = 0; s < ms->nsprings; s++) {
    double l = v3_dist(x + 3 * ms->springs[s].i, x + 3 * ms->springs[s].j) - ms->springs[s].rest;
    e += 0.5 * (ms->k_scale ? ms->p.stiffness * ms->k_scale[s] : ms->p.stiffness) * l * l;
  }
  return e;
}

double mass_spring_energy(const mass_spring_t *ms) {
  double e = mass_spring_potential(ms, ms->x);
  for (size_t i = 0; i < ms->n; i++) e += 0.5 * ms->mass[i] * v3_dot(ms->v + 3 * i, ms->v + 3 * i);
  return e;
}

double mass_spring_max_strain(const mass_spring_t *ms) {
  double m = 0;
  for (size_t s = 0; s < ms->nsprings; s++) {
    const ms_spring_t *sp = &ms->springs[s];
    if (!(sp->rest > 0)) continue;
    double e = fabs(v3_dist(ms->x + 3 * sp->i, ms->x + 3 * sp->j) / sp->rest - 1);
    if (e > m) m = e;
  }
  return m;
}

int mass_spring_set_stiffness_scale(mass_spring_t *ms, const double *scale, verr_t *err) {
  if (!scale) {
    free(ms->k_scale);
    ms->k_scale = NULL;
    return 0;
  }
  for (size_t s = 0; s < ms->nsprings; s++)
    if (!(scale[s] >= 0) || !isfinite(scale[s]))
      return verr_set(err, "mass-spring: stiffness factor of spring %zu must be finite and >= 0 (got %g)", s, scale[s]);
  double *k = realloc(ms->k_scale, (ms->nsprings + 1) * sizeof(double));
  if (!k) return verr_set(err, "mass-spring: out of memory for %zu stiffness factors", ms->nsprings);
  memcpy(k, scale, ms->nsprings * sizeof(double));
  ms->k_scale = k;
  return 0;
}
