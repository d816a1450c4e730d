/* SPDX-License-Identifier: Apache-2.0 */
#include "physics/molecular.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "vmath.h"

/* Regularised length sqrt(|d|^2 + eps^2) (see molecular.h): smooth at d = 0,
 * so every quotient below has a denominator of at least eps. */
static inline double reg_len(const double *d, double eps2) { return sqrt(v3_dot(d, d) + eps2); }

int molecular_check_params(double k_r, double k_theta, double k_sb, verr_t *err) {
  if (!isfinite(k_r) || !isfinite(k_theta) || !isfinite(k_sb))
    return verr_set(err, "molecular: bond_k, angle_k and stretch_bend_k must be finite (got %g, %g, %g)", k_r, k_theta,
                    k_sb);
  if (!(k_r > 0) || !(k_theta > 0))
    return verr_set(err, "molecular: bond_k and angle_k must be > 0 (got bond_k %g, angle_k %g)", k_r, k_theta);
  /* Determinant of the per-angle quadratic form over (dr_a, dr_b, dcos)
   * of eq. 6, 9 and 11: k_r (k_r k_theta - 2 k_sb^2) (molecular.h). */
  double lhs = k_r * k_theta, rhs = 2 * k_sb * k_sb;
  if (!(lhs > rhs))
    return verr_set(err,
                    "molecular: bond_k * angle_k = %g * %g = %g must exceed 2 * stretch_bend_k^2 = 2 * %g^2 = %g, "
                    "otherwise the stretch-bend energy (docs/methods.md A eq. 11) is not positive-definite",
                    k_r, k_theta, lhs, k_sb, rhs);
  return 0;
}

/* Half-edge record for the unique-edge build: (min vertex, max vertex,
 * 3 * triangle + edge). Sorting by all three puts each edge's first
 * triangle first, which then owns the bond. */
static int edge_cmp(const void *pa, const void *pb) {
  const uint32_t *a = pa, *b = pb;
  for (int k = 0; k < 3; k++)
    if (a[k] != b[k]) return a[k] < b[k] ? -1 : 1;
  return 0;
}

static void fs_forces(force_system_t *s, const double *x, const double *v, double *f) {
  molecular_forces(s->ctx, x, v, f);
}

static void fs_stiffness_mul(force_system_t *s, const double *x, double a, double b, const double *y, double *out) {
  molecular_stiffness_mul(s->ctx, x, a, b, y, out);
}

int molecular_create(molecular_t *m, const mesh_t *s, const mol_params_t *p, verr_t *err) {
  memset(m, 0, sizeof *m);
  if (molecular_check_params(p->bond_k, p->angle_k, p->stretch_bend_k, err)) return -1;
  if (!(p->mass > 0) || !isfinite(p->mass) || !(p->bond_damping >= 0) || !(p->home_stiffness >= 0) ||
      !(p->home_damping >= 0) || !isfinite(p->bond_damping) || !isfinite(p->home_stiffness) ||
      !isfinite(p->home_damping) || !v3_isfinite(p->gravity))
    return verr_set(err, "molecular: mass must be > 0 and damping / home stiffness finite and >= 0");
  if (s->nverts == 0 || s->ntris == 0) return verr_set(err, "molecular: mesh has no triangles");
  if (s->nverts > UINT32_MAX || s->ntris > UINT32_MAX / 3) /* indices and 3 t + k fit in 32 bits */
    return verr_set(err, "molecular: too many vertices or triangles (%zu, %zu)", s->nverts, s->ntris);
  for (size_t t = 0; t < 3 * s->ntris; t++)
    if (s->tris[t] >= s->nverts)
      return verr_set(err, "molecular: triangle %zu uses vertex %u of %zu", t / 3, s->tris[t], s->nverts);
  size_t n = s->nverts, nt = s->ntris;
  m->n = n;
  m->ntris = nt;
  m->p = *p;
  m->x = calloc(3 * n, sizeof(double));
  m->v = calloc(3 * n, sizeof(double));
  m->x_rest = calloc(3 * n, sizeof(double));
  m->f_ext = calloc(3 * n, sizeof(double));
  m->mass = calloc(n, sizeof(double));
  m->inv_mass = calloc(n, sizeof(double));
  m->tris = calloc(nt, sizeof(mol_tri_t));
  m->tri_idx = calloc(3 * nt, sizeof(uint32_t));
  uint32_t *edges = malloc(9 * nt * sizeof(uint32_t));
  if (!m->x || !m->v || !m->x_rest || !m->f_ext || !m->mass || !m->inv_mass || !m->tris || !m->tri_idx || !edges) {
    free(edges);
    molecular_destroy(m);
    return verr_set(err, "molecular: out of memory for %zu vertices", n);
  }
  memcpy(m->x, s->pos, 3 * n * sizeof(double));
  memcpy(m->x_rest, s->pos, 3 * n * sizeof(double));
  memcpy(m->tri_idx, s->tris, 3 * nt * sizeof(uint32_t));

  double area = 0;
  for (size_t t = 0; t < nt; t++) {
    const uint32_t *f = s->tris + 3 * t;
    double e1[3], e2[3], c[3];
    v3_sub(e1, s->pos + 3 * f[1], s->pos + 3 * f[0]);
    v3_sub(e2, s->pos + 3 * f[2], s->pos + 3 * f[0]);
    v3_cross(c, e1, e2);
    area += 0.5 * v3_norm(c);
    for (int k = 0; k < 3; k++) {
      uint32_t i = f[k], j = f[(k + 1) % 3], *r = edges + 9 * t + 3 * k;
      r[0] = i < j ? i : j;
      r[1] = i < j ? j : i;
      r[2] = (uint32_t)(3 * t + k);
    }
  }
  if (!(area > 0) || !isfinite(area)) {
    free(edges);
    molecular_destroy(m);
    return verr_set(err, "molecular: mesh has zero (or non-finite) surface area");
  }
  /* Unique edges: sort the 3T half-edges, keep the first of each run and
   * mark its triangle as the bond's owner. */
  size_t ne = 3 * nt, nb = 0;
  qsort(edges, ne, 3 * sizeof(uint32_t), edge_cmp);
  uint32_t prev0 = 0, prev1 = 0; /* (0, 0) is never a bond */
  for (size_t e = 0; e < ne; e++) {
    uint32_t a = edges[3 * e], b = edges[3 * e + 1], slot = edges[3 * e + 2];
    if (a == b) continue; /* repeated index in a triangle: no bond */
    if (a == prev0 && b == prev1) continue;
    prev0 = a;
    prev1 = b;
    m->tris[slot / 3].owns |= 1u << (slot % 3);
    edges[2 * nb] = a; /* compacted in place: 2 nb + 1 <= 3 e + 2, read before written */
    edges[2 * nb + 1] = b;
    nb++;
  }
  m->bonds = calloc(nb + 1, sizeof(mol_bond_t));
  if (!m->bonds) {
    free(edges);
    molecular_destroy(m);
    return verr_set(err, "molecular: out of memory for %zu bonds", nb);
  }
  m->nbonds = nb;
  double mean = 0;
  for (size_t b = 0; b < nb; b++) mean += v3_dist(s->pos + 3 * edges[2 * b], s->pos + 3 * edges[2 * b + 1]);
  mean = nb ? mean / (double)nb : 0;
  if (!(mean > 0)) {
    free(edges);
    molecular_destroy(m);
    return verr_set(err, "molecular: mesh has no bond of positive length");
  }
  m->eps2 = (1e-4 * mean) * (1e-4 * mean);
  for (size_t b = 0; b < nb; b++) {
    mol_bond_t *bd = &m->bonds[b];
    bd->i = edges[2 * b];
    bd->j = edges[2 * b + 1];
    double d[3];
    v3_sub(d, s->pos + 3 * bd->j, s->pos + 3 * bd->i);
    bd->r0 = reg_len(d, m->eps2);
  }
  free(edges);
  /* Rest lengths and cosines with the same regularised measure as the
   * forces, so the rest shape is an exact equilibrium. */
  for (size_t t = 0; t < nt; t++) {
    mol_tri_t *tr = &m->tris[t];
    double e[3][3], l[3];
    for (int k = 0; k < 3; k++) tr->v[k] = s->tris[3 * t + k];
    for (int k = 0; k < 3; k++) {
      v3_sub(e[k], s->pos + 3 * tr->v[(k + 1) % 3], s->pos + 3 * tr->v[k]);
      l[k] = reg_len(e[k], m->eps2);
      tr->r0[k] = l[k];
    }
    for (int k = 0; k < 3; k++) {
      int kp = (k + 2) % 3; /* the edge arriving at corner k, reversed: b = -e[kp] */
      tr->c0[k] = -v3_dot(e[k], e[kp]) / (l[k] * l[kp]);
    }
  }
  /* Equal lumped masses (docs/methods.md A: equal point masses, as in mass_spring.c). */
  for (size_t i = 0; i < n; i++) {
    m->mass[i] = p->mass / (double)n;
    m->inv_mass[i] = 1.0 / m->mass[i];
  }
  m->fs = (force_system_t){.n = n,
                           .x = m->x,
                           .v = m->v,
                           .mass = m->mass,
                           .inv_mass = m->inv_mass,
                           .forces = fs_forces,
                           .stiffness_mul = fs_stiffness_mul,
                           .pre_substep = NULL,
                           .ctx = m};
  return 0;
}

void molecular_destroy(molecular_t *m) {
  free(m->x);
  free(m->v);
  free(m->x_rest);
  free(m->f_ext);
  free(m->mass);
  free(m->inv_mass);
  free(m->bonds);
  free(m->tris);
  free(m->tri_idx);
  memset(m, 0, sizeof *m);
}

size_t molecular_fix_below(molecular_t *m, double z) {
  size_t count = 0;
  for (size_t i = 0; i < m->n; i++)
    if (m->x_rest[3 * i + 2] < z) {
      m->inv_mass[i] = 0;
      count++;
    }
  return count;
}

/* The triangle kernels work on scalars and small structs passed by value,
 * not on 3x3 arrays: the compiler then keeps everything in registers (with
 * arrays GCC -O2 stored lengths one by one and reloaded them in pairs, which
 * stalls store forwarding and cost a third of the time). */
typedef struct d3 {
  double x, y, z;
} d3;
static inline d3 d3_at(const double *p, uint32_t i) {
  return (d3){p[3 * (size_t)i], p[3 * (size_t)i + 1], p[3 * (size_t)i + 2]};
}
static inline d3 d3_minus(d3 a, d3 b) { return (d3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static inline double d3_dot(d3 a, d3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
/* c0 a + c1 b + c2 c */
static inline d3 d3_comb(double c0, d3 a, double c1, d3 b, double c2, d3 c) {
  return (d3){c0 * a.x + c1 * b.x + c2 * c.x, c0 * a.y + c1 * b.y + c2 * c.y, c0 * a.z + c1 * b.z + c2 * c.z};
}
static inline void d3_acc(double *p, uint32_t i, d3 a) {
  p[3 * (size_t)i] += a.x;
  p[3 * (size_t)i + 1] += a.y;
  p[3 * (size_t)i + 2] += a.z;
}

/* What every triangle kernel (forces, stiffness product, fused right-hand
 * side) starts from: the edge vectors e_k = x_{k+1} - x_k, the regularised
 * lengths l_k = sqrt(e_k.e_k + eps^2), their inverses (one division for
 * the three) and the stretches dr_k = l_k - r0_k. One helper, so the
 * kernels stay bit for bit consistent (test_molecular). Always inlined:
 * merely inline, GCC -O2 kept the returned struct in memory and the force
 * kernel took 6-7 % longer (127 -> 136 us on the kidney); inlined, the
 * three kernels time as before (forces 125-127 us, fused rhs 187-188
 * against 190-192, stiffness product 191-193 against 194-197, best of
 * 30 x 100 calls, three pairs against main, load 8-10). */
typedef struct tri_geom {
  d3 e0, e1, e2;
  double il0, il1, il2, dr0, dr1, dr2;
} tri_geom;

__attribute__((always_inline)) static inline tri_geom tri_setup(const double *x, const mol_tri_t *tr, double eps2) {
  const d3 x0 = d3_at(x, tr->v[0]), x1 = d3_at(x, tr->v[1]), x2 = d3_at(x, tr->v[2]);
  tri_geom g;
  g.e0 = d3_minus(x1, x0);
  g.e1 = d3_minus(x2, x1);
  g.e2 = d3_minus(x0, x2);
  const double l0 = sqrt(d3_dot(g.e0, g.e0) + eps2), l1 = sqrt(d3_dot(g.e1, g.e1) + eps2);
  const double l2 = sqrt(d3_dot(g.e2, g.e2) + eps2);
  const double inv = 1.0 / (l0 * l1 * l2);
  g.il0 = l1 * l2 * inv;
  g.il1 = l0 * l2 * inv;
  g.il2 = l0 * l1 * inv;
  g.dr0 = l0 - tr->r0[0];
  g.dr1 = l1 - tr->r0[1];
  g.dr2 = l2 - tr->r0[2];
  return g;
}

/* One corner (eq. 9 and 11): a = e_k and b = -e_m (m = k + 2, the bond
 * arriving at the corner, reversed), given a.b, the inverse lengths and the
 * stretches. Adds dE/da = A b + Ba a and dE/db = A a + Bb b to the edge
 * coefficients: caa of e_k in dE/de_k, cbb of e_m in dE/de_m, and cab (the
 * symmetric off-diagonal) -A. With gc = dE/dc = k_theta dc + k_sb (dr_a +
 * dr_b) and gr = dE/dr_a = dE/dr_b = k_sb dc:
 *   c = a.b / (la lb),  dc/da = b / (la lb) - c a / la^2
 * (no acos, no 1/sin: finite at 0 and 180 degrees, where it vanishes, and
 * bounded by 2/eps for short bonds), so
 *   A = gc / (la lb),  Ba = (gr - gc c / la) / la,  Bb likewise. */
static inline void corner(double ab, double ila, double ilb, double dra, double drb, double c0, double kt, double ksb,
                          double *caa, double *cbb, double *cab) {
  double alpha = ila * ilb;
  double c = ab * alpha, dc = c - c0;
  double gc = kt * dc + ksb * (dra + drb), gr = ksb * dc;
  *cab -= gc * alpha;
  *caa += (gr - gc * c * ila) * ila;
  *cbb += (gr - gc * c * ilb) * ilb;
}

/* Every term of a triangle is a function of its edge vectors e_k = x_{k+1}
 * - x_k, and every gradient a combination of them: dE/de_k = sum_m C_km e_m
 * with C symmetric; vertex k then gets the force G_k - G_{k+2}, G_k =
 * dE/de_k. An owned bond k (eq. 6, 8) adds k_r dr_k / l_k to C_kk (its
 * gradient is k_r dr e / l), and its damping c_b (e.dv) / l^2 likewise. */
void molecular_forces(const molecular_t *m, const double *x, const double *v, double *f) {
  const mol_params_t *p = &m->p;
  const double kh = p->home_stiffness, ch = p->home_damping;
  for (size_t i = 0; i < m->n; i++) {
    const double *xi = x + 3 * i, *vi = v + 3 * i, *xr = m->x_rest + 3 * i, *fe = m->f_ext + 3 * i;
    double mi = m->mass[i];
    for (int k = 0; k < 3; k++) f[3 * i + k] = fe[k] + mi * p->gravity[k] - kh * (xi[k] - xr[k]) - ch * vi[k];
  }
  const double kr = p->bond_k, cb = p->bond_damping, eps2 = m->eps2;
  const double kt = p->angle_k, ksb = p->stretch_bend_k;
  const int angles = kt != 0 || ksb != 0;
  for (size_t t = 0; t < m->ntris; t++) {
    const mol_tri_t *tr = &m->tris[t];
    const uint32_t i0 = tr->v[0], i1 = tr->v[1], i2 = tr->v[2];
    const tri_geom g = tri_setup(x, tr, eps2);
    const d3 e0 = g.e0, e1 = g.e1, e2 = g.e2;
    const double il0 = g.il0, il1 = g.il1, il2 = g.il2, dr0 = g.dr0, dr1 = g.dr1, dr2 = g.dr2;
    double c00 = 0, c11 = 0, c22 = 0, c01 = 0, c12 = 0, c02 = 0;
    const uint32_t owns = tr->owns;
    if (owns) {
      if (owns & 1u)
        c00 += (kr * dr0 + (cb != 0 ? cb * d3_dot(e0, d3_minus(d3_at(v, i1), d3_at(v, i0))) * il0 : 0)) * il0;
      if (owns & 2u)
        c11 += (kr * dr1 + (cb != 0 ? cb * d3_dot(e1, d3_minus(d3_at(v, i2), d3_at(v, i1))) * il1 : 0)) * il1;
      if (owns & 4u)
        c22 += (kr * dr2 + (cb != 0 ? cb * d3_dot(e2, d3_minus(d3_at(v, i0), d3_at(v, i2))) * il2 : 0)) * il2;
    }
    if (angles) {
      /* Corner 0: a = e0, b = -e2; corner 1: a = e1, b = -e0; corner 2: a = e2, b = -e1. */
      corner(-d3_dot(e0, e2), il0, il2, dr0, dr2, tr->c0[0], kt, ksb, &c00, &c22, &c02);
      corner(-d3_dot(e1, e0), il1, il0, dr1, dr0, tr->c0[1], kt, ksb, &c11, &c00, &c01);
      corner(-d3_dot(e2, e1), il2, il1, dr2, dr1, tr->c0[2], kt, ksb, &c22, &c11, &c12);
    }
    const d3 G0 = d3_comb(c00, e0, c01, e1, c02, e2);
    const d3 G1 = d3_comb(c01, e0, c11, e1, c12, e2);
    const d3 G2 = d3_comb(c02, e0, c12, e1, c22, e2);
    d3_acc(f, i0, d3_minus(G0, G2));
    d3_acc(f, i1, d3_minus(G1, G0));
    d3_acc(f, i2, d3_minus(G2, G1));
  }
}

/* Derivative of corner() along y (forward mode, see molecular_stiffness_mul):
 * given d(a.b) = abd and the length rates ldot = lad, lbd of the two bonds, adds the
 * coefficients of corner() (caa, cbb, cab) and their derivatives (daa, dbb,
 * dab). geo = 0 drops the curvature terms (those multiplying gc or gr
 * themselves rather than their derivatives): the Gauss-Newton part. */
static inline void corner_d(double ab, double abd, double ila, double ilb, double lad, double lbd, double dra,
                            double drb, double c0, double kt, double ksb, double geo, double *caa, double *cbb,
                            double *cab, double *daa, double *dbb, double *dab) {
  double alpha = ila * ilb;
  double alphad = -alpha * (lad * ila + lbd * ilb);
  double c = ab * alpha, cd = abd * alpha + ab * alphad;
  double dc = c - c0;
  double gc = geo * (kt * dc + ksb * (dra + drb)), gcd = kt * cd + ksb * (lad + lbd);
  double gr = geo * ksb * dc, grd = ksb * cd;
  double pa = gr - gc * c * ila, pb = gr - gc * c * ilb;
  double pad = grd - (gcd * c + gc * cd) * ila + gc * c * lad * ila * ila;
  double pbd = grd - (gcd * c + gc * cd) * ilb + gc * c * lbd * ilb * ilb;
  *cab -= gc * alpha;
  *dab -= gcd * alpha + gc * alphad;
  *caa += pa * ila;
  *cbb += pb * ilb;
  *daa += (pad - pa * lad * ila) * ila;
  *dbb += (pbd - pb * lbd * ilb) * ilb;
}

/* K y is the derivative along y of the gradient the kernel above builds
 * (forward mode): with edot_k = y_{k+1} - y_k and ldot_k = e_k . edot_k / l_k,
 *   d/dt (C e) = Cdot e + C edot,
 * term by term:
 *   bond:   d(k_r dr / l) = k_r ldot (1 - dr / l) / l
 *   corner: alphadot = -alpha (ladot / la + lbdot / lb),
 *           cdot = d(a.b) alpha + (a.b) alphadot,
 *           gcdot = k_theta cdot + k_sb (ladot + lbdot), grdot = k_sb cdot,
 *           Adot = gcdot alpha + gc alphadot,
 *           Pa = gr - gc c / la,  Padot = grdot - (gcdot c + gc cdot) / la
 *                                        + gc c ladot / la^2,
 *           Badot = (Padot - Pa ladot / la) / la.
 * The damping part (b C y) is the bond damping c_b (u . edot) u plus the
 * ground damping; it has no x derivative here (molecular.h). With
 * definite_jacobian the curvature terms are dropped (geo = 0 below). */
void molecular_stiffness_mul(const molecular_t *m, const double *x, double a_k, double b_c, const double *y,
                             double *out) {
  const mol_params_t *p = &m->p;
  const double diag = a_k * p->home_stiffness + b_c * p->home_damping;
  for (size_t c = 0; c < 3 * m->n; c++) out[c] = diag * y[c];
  const double kr = p->bond_k, cb = p->bond_damping, eps2 = m->eps2;
  const double kt = p->angle_k, ksb = p->stretch_bend_k;
  if (a_k == 0) {
    /* Damping only: one pass over the bonds. */
    if (b_c == 0 || cb == 0) return;
    for (size_t b = 0; b < m->nbonds; b++) {
      const mol_bond_t *bd = &m->bonds[b];
      double d[3], yd[3];
      v3_sub(d, x + 3 * bd->j, x + 3 * bd->i);
      v3_sub(yd, y + 3 * bd->j, y + 3 * bd->i);
      double s = b_c * cb * v3_dot(d, yd) / (v3_dot(d, d) + eps2);
      v3_axpy(out + 3 * bd->j, d, s);
      v3_axpy(out + 3 * bd->i, d, -s);
    }
    return;
  }
  const int angles = kt != 0 || ksb != 0;
  const double geo = m->definite_jacobian ? 0 : 1;
  for (size_t t = 0; t < m->ntris; t++) {
    const mol_tri_t *tr = &m->tris[t];
    const uint32_t i0 = tr->v[0], i1 = tr->v[1], i2 = tr->v[2];
    const tri_geom g = tri_setup(x, tr, eps2);
    const d3 e0 = g.e0, e1 = g.e1, e2 = g.e2;
    const double il0 = g.il0, il1 = g.il1, il2 = g.il2, dr0 = g.dr0, dr1 = g.dr1, dr2 = g.dr2;
    const d3 y0 = d3_at(y, i0), y1 = d3_at(y, i1), y2 = d3_at(y, i2);
    const d3 f0 = d3_minus(y1, y0), f1 = d3_minus(y2, y1), f2 = d3_minus(y0, y2); /* edot */
    const double ld0 = d3_dot(e0, f0) * il0, ld1 = d3_dot(e1, f1) * il1, ld2 = d3_dot(e2, f2) * il2;
    double c00 = 0, c11 = 0, c22 = 0, c01 = 0, c12 = 0, c02 = 0;
    double d00 = 0, d11 = 0, d22 = 0, d01 = 0, d12 = 0, d02 = 0;
    const uint32_t owns = tr->owns;
    if (owns & 1u) {
      c00 += geo * a_k * kr * dr0 * il0;
      d00 += (a_k * kr * (1 - geo * dr0 * il0) + b_c * cb) * ld0 * il0;
    }
    if (owns & 2u) {
      c11 += geo * a_k * kr * dr1 * il1;
      d11 += (a_k * kr * (1 - geo * dr1 * il1) + b_c * cb) * ld1 * il1;
    }
    if (owns & 4u) {
      c22 += geo * a_k * kr * dr2 * il2;
      d22 += (a_k * kr * (1 - geo * dr2 * il2) + b_c * cb) * ld2 * il2;
    }
    if (angles) {
      const double akt = a_k * kt, aksb = a_k * ksb; /* K is linear in the constants */
      corner_d(-d3_dot(e0, e2), -d3_dot(f0, e2) - d3_dot(e0, f2), il0, il2, ld0, ld2, dr0, dr2, tr->c0[0], akt, aksb,
               geo, &c00, &c22, &c02, &d00, &d22, &d02);
      corner_d(-d3_dot(e1, e0), -d3_dot(f1, e0) - d3_dot(e1, f0), il1, il0, ld1, ld0, dr1, dr0, tr->c0[1], akt, aksb,
               geo, &c11, &c00, &c01, &d11, &d00, &d01);
      corner_d(-d3_dot(e2, e1), -d3_dot(f2, e1) - d3_dot(e2, f1), il2, il1, ld2, ld1, dr2, dr1, tr->c0[2], akt, aksb,
               geo, &c22, &c11, &c12, &d22, &d11, &d12);
    }
    const d3 Ge0 = d3_comb(d00, e0, d01, e1, d02, e2), Gf0 = d3_comb(c00, f0, c01, f1, c02, f2);
    const d3 Ge1 = d3_comb(d01, e0, d11, e1, d12, e2), Gf1 = d3_comb(c01, f0, c11, f1, c12, f2);
    const d3 Ge2 = d3_comb(d02, e0, d12, e1, d22, e2), Gf2 = d3_comb(c02, f0, c12, f1, c22, f2);
    const d3 G0 = {Ge0.x + Gf0.x, Ge0.y + Gf0.y, Ge0.z + Gf0.z};
    const d3 G1 = {Ge1.x + Gf1.x, Ge1.y + Gf1.y, Ge1.z + Gf1.z};
    const d3 G2 = {Ge2.x + Gf2.x, Ge2.y + Gf2.y, Ge2.z + Gf2.z};
    /* The gradient at vertex k is G_{k+2} - G_k (minus the force). */
    d3_acc(out, i0, d3_minus(G2, G0));
    d3_acc(out, i1, d3_minus(G0, G1));
    d3_acc(out, i2, d3_minus(G1, G2));
  }
}

/* rhs = h F(x, v) - h^2 K_GN v in one pass over the triangles: the force
 * kernel's coefficients (corner) and the Gauss-Newton product's derivative
 * coefficients (corner_d with geo = 0) share the edge vectors, lengths,
 * inverse lengths and cosines, which the two separate passes computed
 * twice (a square root per edge and a divide per triangle each). */
void molecular_linear_rhs(const molecular_t *m, double h, double *rhs) {
  const mol_params_t *p = &m->p;
  const double *x = m->x, *v = m->v;
  const double kh = p->home_stiffness, ch = p->home_damping, a_k = h * h;
  for (size_t i = 0; i < m->n; i++) {
    const double *xi = x + 3 * i, *vi = v + 3 * i, *xr = m->x_rest + 3 * i, *fe = m->f_ext + 3 * i;
    double mi = m->mass[i];
    for (int k = 0; k < 3; k++)
      rhs[3 * i + k] = h * (fe[k] + mi * p->gravity[k] - kh * (xi[k] - xr[k]) - ch * vi[k]) - a_k * kh * vi[k];
  }
  const double kr = p->bond_k, cb = p->bond_damping, eps2 = m->eps2;
  const double kt = p->angle_k, ksb = p->stretch_bend_k, akt = a_k * kt, aksb = a_k * ksb;
  const int angles = kt != 0 || ksb != 0;
  for (size_t t = 0; t < m->ntris; t++) {
    const mol_tri_t *tr = &m->tris[t];
    const uint32_t i0 = tr->v[0], i1 = tr->v[1], i2 = tr->v[2];
    const tri_geom g = tri_setup(x, tr, eps2);
    const d3 e0 = g.e0, e1 = g.e1, e2 = g.e2;
    const double il0 = g.il0, il1 = g.il1, il2 = g.il2, dr0 = g.dr0, dr1 = g.dr1, dr2 = g.dr2;
    const d3 v0 = d3_at(v, i0), v1 = d3_at(v, i1), v2 = d3_at(v, i2);
    const d3 f0 = d3_minus(v1, v0), f1 = d3_minus(v2, v1), f2 = d3_minus(v0, v2);
    const double ld0 = d3_dot(e0, f0) * il0, ld1 = d3_dot(e1, f1) * il1, ld2 = d3_dot(e2, f2) * il2;
    /* c: the force's coefficients (molecular_forces); d: h^2 K_GN v's. */
    double c00 = 0, c11 = 0, c22 = 0, c01 = 0, c12 = 0, c02 = 0;
    double d00 = 0, d11 = 0, d22 = 0, d01 = 0, d12 = 0, d02 = 0;
    double z00 = 0, z11 = 0, z22 = 0, z01 = 0, z12 = 0, z02 = 0; /* Gauss-Newton: the product's c part is 0 */
    const uint32_t owns = tr->owns;
    if (owns & 1u) {
      c00 += (kr * dr0 + cb * ld0) * il0;
      d00 += a_k * kr * ld0 * il0;
    }
    if (owns & 2u) {
      c11 += (kr * dr1 + cb * ld1) * il1;
      d11 += a_k * kr * ld1 * il1;
    }
    if (owns & 4u) {
      c22 += (kr * dr2 + cb * ld2) * il2;
      d22 += a_k * kr * ld2 * il2;
    }
    if (angles) {
      const double ab0 = -d3_dot(e0, e2), ab1 = -d3_dot(e1, e0), ab2 = -d3_dot(e2, e1);
      corner(ab0, il0, il2, dr0, dr2, tr->c0[0], kt, ksb, &c00, &c22, &c02);
      corner(ab1, il1, il0, dr1, dr0, tr->c0[1], kt, ksb, &c11, &c00, &c01);
      corner(ab2, il2, il1, dr2, dr1, tr->c0[2], kt, ksb, &c22, &c11, &c12);
      corner_d(ab0, -d3_dot(f0, e2) - d3_dot(e0, f2), il0, il2, ld0, ld2, dr0, dr2, tr->c0[0], akt, aksb, 0, &z00, &z22,
               &z02, &d00, &d22, &d02);
      corner_d(ab1, -d3_dot(f1, e0) - d3_dot(e1, f0), il1, il0, ld1, ld0, dr1, dr0, tr->c0[1], akt, aksb, 0, &z11, &z00,
               &z01, &d11, &d00, &d01);
      corner_d(ab2, -d3_dot(f2, e1) - d3_dot(e2, f1), il2, il1, ld2, ld1, dr2, dr1, tr->c0[2], akt, aksb, 0, &z22, &z11,
               &z12, &d22, &d11, &d12);
    }
    /* Force at vertex k: G_k - G_{k+2} with G = C e; K v at k: D_{k+2} - D_k
     * with D = d e. rhs gets h (force) - (K v): h (c e)_k - h (c e)_{k+2} +
     * (d e)_k - (d e)_{k+2}, so one combined coefficient set h c + d. */
    const double q00 = h * c00 + d00, q11 = h * c11 + d11, q22 = h * c22 + d22;
    const double q01 = h * c01 + d01, q12 = h * c12 + d12, q02 = h * c02 + d02;
    const d3 G0 = d3_comb(q00, e0, q01, e1, q02, e2);
    const d3 G1 = d3_comb(q01, e0, q11, e1, q12, e2);
    const d3 G2 = d3_comb(q02, e0, q12, e1, q22, e2);
    d3_acc(rhs, i0, d3_minus(G0, G2));
    d3_acc(rhs, i1, d3_minus(G1, G0));
    d3_acc(rhs, i2, d3_minus(G2, G1));
  }
}

double molecular_potential(const molecular_t *m, const double *x) {
  const mol_params_t *p = &m->p;
  double e = 0;
  for (size_t i = 0; i < m->n; i++) {
    double d[3];
    v3_sub(d, x + 3 * i, m->x_rest + 3 * i);
    e += 0.5 * p->home_stiffness * v3_dot(d, d) - m->mass[i] * v3_dot(p->gravity, x + 3 * i);
  }
  for (size_t b = 0; b < m->nbonds; b++) {
    double d[3];
    v3_sub(d, x + 3 * m->bonds[b].j, x + 3 * m->bonds[b].i);
    double dr = reg_len(d, m->eps2) - m->bonds[b].r0;
    e += 0.5 * p->bond_k * dr * dr; /* eq. 6 */
  }
  for (size_t t = 0; t < m->ntris; t++) {
    const mol_tri_t *tr = &m->tris[t];
    double ed[3][3], l[3];
    for (int k = 0; k < 3; k++) {
      v3_sub(ed[k], x + 3 * tr->v[(k + 1) % 3], x + 3 * tr->v[k]);
      l[k] = reg_len(ed[k], m->eps2);
    }
    for (int k = 0; k < 3; k++) {
      int k2 = (k + 2) % 3;
      double dc = -v3_dot(ed[k], ed[k2]) / (l[k] * l[k2]) - tr->c0[k];
      e += 0.5 * p->angle_k * dc * dc;                                           /* eq. 9 */
      e += p->stretch_bend_k * dc * ((l[k] - tr->r0[k]) + (l[k2] - tr->r0[k2])); /* eq. 11 */
    }
  }
  return e;
}

double molecular_energy(const molecular_t *m) {
  double e = molecular_potential(m, m->x);
  for (size_t i = 0; i < m->n; i++) e += 0.5 * m->mass[i] * v3_dot(m->v + 3 * i, m->v + 3 * i);
  return e;
}

/* y = M^-1 (a K_rest + b C + extra I) x on the free vertices. */
static void rest_apply(const molecular_t *m, double a, double b, double extra, const double *x, double *y) {
  molecular_stiffness_mul(m, m->x_rest, a, b, x, y);
  for (size_t c = 0; c < 3 * m->n; c++) y[c] = (y[c] + extra * x[c]) * m->inv_mass[c / 3];
}

/* Largest eigenvalue of M^-1 A (A symmetric, M diagonal: real spectrum) by
 * power iteration, with the M-weighted Rayleigh quotient x^T A x / x^T M x
 * as the estimate (it converges twice as fast as the norm ratio). */
static double power_lambda(const molecular_t *m, double a, double b, double extra, double *x, double *y) {
  size_t n3 = 3 * m->n;
  unsigned seed = 2463534242u;
  for (size_t c = 0; c < n3; c++) {
    seed ^= seed << 13;
    seed ^= seed >> 17;
    seed ^= seed << 5;
    x[c] = ((double)seed / 4294967296.0 - 0.5) * (m->inv_mass[c / 3] > 0);
  }
  double lambda = 0;
  /* The quotient rises monotonically; on the gallbladder it is within 1 %
   * after 30 iterations and gains under 2e-5 per iteration after about 200,
   * well inside the 2 % margin. */
  for (int it = 0; it < 300; it++) {
    double xmx = 0;
    for (size_t c = 0; c < n3; c++) xmx += m->mass[c / 3] * x[c] * x[c];
    if (!(xmx > 0)) return 0;
    rest_apply(m, a, b, extra, x, y);
    double xay = 0, ny = 0;
    for (size_t c = 0; c < n3; c++) {
      xay += m->mass[c / 3] * x[c] * y[c];
      ny += y[c] * y[c];
    }
    double next = fabs(xay) / xmx;
    ny = sqrt(ny);
    if (!(ny > 0)) return 0;
    for (size_t c = 0; c < n3; c++) x[c] = y[c] / ny;
    int done = it > 20 && fabs(next - lambda) <= 2e-5 * next;
    lambda = next;
    if (done) break;
  }
  return 1.02 * lambda;
}

int molecular_rest_lambdas(const molecular_t *m, double extra_home, double *lambda_k, double *lambda_c) {
  double *x = malloc((6 * m->n + 1) * sizeof(double));
  if (!x) return -1;
  *lambda_k = power_lambda(m, 1, 0, extra_home, x, x + 3 * m->n);
  *lambda_c = power_lambda(m, 0, 1, 0, x, x + 3 * m->n);
  free(x);
  return 0;
}

double molecular_max_strain(const molecular_t *m) {
  double worst = 0;
  for (size_t b = 0; b < m->nbonds; b++) {
    const mol_bond_t *bd = &m->bonds[b];
    double d[3];
    v3_sub(d, m->x + 3 * bd->j, m->x + 3 * bd->i);
    double s = fabs(reg_len(d, m->eps2) / bd->r0 - 1);
    if (s > worst) worst = s;
  }
  return worst;
}
