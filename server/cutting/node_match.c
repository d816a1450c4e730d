/* SPDX-License-Identifier: Apache-2.0 */
#include "cutting/node_match.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cutting/bezier.h"
#include "vmath.h"

#define NM_TABLE 256 /* arc-length table samples */
#define NM_NEAREST_SAMPLES 128
#define NM_SLIVER_DEG 15.0 /* smallest angle below which the zipper looks at the other move */

/* Growable arrays (the result's and the work lists). */
typedef struct u32vec {
  uint32_t *p;
  size_t n, cap;
} u32vec_t;

static int u32_push(u32vec_t *v, uint32_t x) {
  if (v->n == v->cap) {
    size_t cap = v->cap ? 2 * v->cap : 16;
    uint32_t *p = realloc(v->p, cap * sizeof *p);
    if (!p) return -1;
    v->p = p;
    v->cap = cap;
  }
  v->p[v->n++] = x;
  return 0;
}

typedef struct ctx {
  size_t n;
  const double *x;
  const double (*ctrl)[3];
  double merge_tol;
  double s_tab[NM_TABLE + 1]; /* arc length at a = i / NM_TABLE */
  double total;
  u32vec_t tris, match_node, match_to;
  double *a;
  size_t nnew, acap;
  nm_lip_t *lips;
  size_t nlips, lipcap;
  size_t open_left;
} ctx_t;

static double arc_of(const ctx_t *c, double a) {
  double f = a * NM_TABLE;
  int i = (int)f;
  if (i >= NM_TABLE) return c->total;
  if (i < 0) return 0;
  return c->s_tab[i] + (f - i) * (c->s_tab[i + 1] - c->s_tab[i]);
}

static double param_of(const ctx_t *c, double s) {
  if (s <= 0) return 0;
  if (s >= c->total) return 1;
  int lo = 0, hi = NM_TABLE;
  while (hi - lo > 1) {
    int mid = (lo + hi) / 2;
    if (c->s_tab[mid] <= s)
      lo = mid;
    else
      hi = mid;
  }
  double ds = c->s_tab[hi] - c->s_tab[lo];
  return ((double)lo + (ds > 0 ? (s - c->s_tab[lo]) / ds : 0)) / NM_TABLE;
}

/* A new curve node at parameter a; returns its index (n + k). */
static int new_node(ctx_t *c, double a, uint32_t *idx) {
  if (c->nnew == c->acap) {
    size_t cap = c->acap ? 2 * c->acap : 16;
    double *p = realloc(c->a, cap * sizeof *p);
    if (!p) return -1;
    c->a = p;
    c->acap = cap;
  }
  c->a[c->nnew] = a;
  *idx = (uint32_t)(c->n + c->nnew++);
  return 0;
}

static int tri(ctx_t *c, uint32_t p, uint32_t q, uint32_t r) {
  return u32_push(&c->tris, p) || u32_push(&c->tris, q) || u32_push(&c->tris, r);
}

static const double *pos(const ctx_t *c, uint32_t i, double buf[3]) {
  if (i < c->n) return c->x + 3 * (size_t)i;
  bezier_eval(c->ctrl, c->a[i - c->n], buf);
  return buf;
}

/* Smallest corner angle of triangle (p, q, r), degrees. */
static double min_angle(const ctx_t *c, uint32_t p, uint32_t q, uint32_t r) {
  double bp[3], bq[3], br[3];
  const double *P[3] = {pos(c, p, bp), pos(c, q, bq), pos(c, r, br)};
  double mn = 180;
  for (int k = 0; k < 3; k++) {
    double u[3], w[3];
    v3_sub(u, P[(k + 1) % 3], P[k]);
    v3_sub(w, P[(k + 2) % 3], P[k]);
    double nu = v3_norm(u), nw = v3_norm(w);
    if (!(nu > 0) || !(nw > 0)) return 0;
    double cs = v3_dot(u, w) / (nu * nw);
    mn = fmin(mn, acos(cs < -1 ? -1 : cs > 1 ? 1 : cs) * (180 / M_PI));
  }
  return mn;
}

static double dist_nodes(const ctx_t *c, uint32_t i, uint32_t j) {
  double bi[3], bj[3];
  return v3_dist(pos(c, i, bi), pos(c, j, bj));
}

/* One side: chain b[0..nb-1] (hole on its left), its lip from end node
 * e_start (curve parameter a0) to e_end (a1), both already created (the same
 * node when the lip is a single point). */
static int do_side(ctx_t *c, const uint32_t *b, size_t nb, double a0, double a1, uint32_t e_start, uint32_t e_end) {
  const int forward = a0 <= a1;
  const double s0 = arc_of(c, a0), span = fabs(arc_of(c, a1) - s0);
  int rc = -1;
  double *s = malloc(nb * sizeof *s); /* arc position of the nearest point, along the lip */
  size_t *order = malloc(nb * sizeof *order);
  uint32_t *match = malloc(nb * sizeof *match); /* lip index each chain node connects to */
  u32vec_t lip = {0};
  if (!s || !order || !match) goto out;
  const double tol = c->merge_tol;
  size_t ncand = 0;
  for (size_t i = 0; i < nb; i++) {
    double arc = arc_of(c, bezier_nearest(c->ctrl, c->x + 3 * (size_t)b[i], NM_NEAREST_SAMPLES, NULL));
    s[i] = forward ? arc - s0 : s0 - arc;
    /* The chain's ends and the nodes nearest the curve's ends (yellow)
     * connect to the end nodes; the others are candidates for lip nodes. */
    if (i == 0 || (i + 1 < nb && s[i] <= tol))
      match[i] = 0;
    else if (i + 1 == nb || s[i] >= span - tol)
      match[i] = UINT32_MAX; /* the last lip node, known below */
    else
      order[ncand++] = i;
  }
  for (size_t i = 1; i < ncand; i++) { /* insertion sort: short, nearly sorted */
    size_t v = order[i], j = i;
    while (j > 0 && s[order[j - 1]] > s[v]) {
      order[j] = order[j - 1];
      j--;
    }
    order[j] = v;
  }
  if (u32_push(&lip, e_start)) goto out;
  /* Groups of nearest points within tol of the group's first one: one lip
   * node each, at the group's mean arc position. */
  for (size_t i = 0; i < ncand;) {
    size_t j = i;
    double sum = 0;
    while (j < ncand && s[order[j]] - s[order[i]] < tol) sum += s[order[j++]];
    double sm = sum / (double)(j - i);
    uint32_t node;
    if (new_node(c, param_of(c, forward ? s0 + sm : s0 - sm), &node) || u32_push(&lip, node)) goto out;
    for (size_t q = i; q < j; q++) match[order[q]] = (uint32_t)(lip.n - 1);
    i = j;
  }
  if (lip.n == 1 && e_end != e_start) {
    /* No chain node chose the inside of the curve: one lip node at its
     * middle all the same, so the two sides of a loop never share a lip
     * edge (they would cover it with the same triangle). */
    uint32_t node;
    if (new_node(c, param_of(c, forward ? s0 + 0.5 * span : s0 - 0.5 * span), &node) || u32_push(&lip, node)) goto out;
  }
  if (e_end != e_start && u32_push(&lip, e_end)) goto out;
  const size_t last = lip.n - 1;
  for (size_t q = 0; q < nb; q++) {
    if (match[q] == UINT32_MAX) match[q] = (uint32_t)last;
    if (u32_push(&c->match_node, b[q]) || u32_push(&c->match_to, lip.p[match[q]])) goto out;
  }
  /* The zipper: in state (bi, cj) chain node bi and lip node cj are joined;
   * each triangle advances one of them. Matches that go backwards (a chain
   * folding on itself) are held at cj, so the strip stays valid. */
  size_t bi = 0, cj = 0;
  while (bi + 1 < nb || cj < last) {
    int adv_chain;
    if (bi + 1 == nb)
      adv_chain = 0;
    else if (cj == last)
      adv_chain = 1;
    else {
      size_t want = match[bi + 1] < cj ? cj : match[bi + 1];
      if (want == cj)
        adv_chain = 1;
      else if (want > cj + 1)
        adv_chain = 0; /* lip nodes no chain node chose: fan them from b_i */
      else             /* the quadrilateral b_i, b_i+1, c_j+1, c_j: split by the shorter diagonal */
        adv_chain = dist_nodes(c, b[bi + 1], lip.p[cj]) <= dist_nodes(c, b[bi], lip.p[cj + 1]);
      /* Quality guard: where the matching's move would make a sliver (a
       * chain node in line with a lip segment, a chain running along the
       * curve) and the other move makes a better triangle, take the other;
       * any order of moves gives a valid strip. */
      double q_chain = min_angle(c, b[bi], b[bi + 1], lip.p[cj]), q_lip = min_angle(c, b[bi], lip.p[cj + 1], lip.p[cj]);
      if ((adv_chain ? q_chain : q_lip) < NM_SLIVER_DEG &&
          (adv_chain ? q_lip : q_chain) > (adv_chain ? q_chain : q_lip))
        adv_chain = !adv_chain;
    }
    if (adv_chain) {
      if (tri(c, b[bi], b[bi + 1], lip.p[cj])) goto out;
      bi++;
    } else {
      if (tri(c, b[bi], lip.p[cj + 1], lip.p[cj])) goto out;
      cj++;
    }
  }
  if (c->nlips == c->lipcap) {
    size_t cap = c->lipcap ? 2 * c->lipcap : 4;
    nm_lip_t *p = realloc(c->lips, cap * sizeof *p);
    if (!p) goto out;
    c->lips = p;
    c->lipcap = cap;
  }
  if (!forward) /* lips are stored from a = 0 to a = 1 */
    for (size_t q = 0; q < lip.n / 2; q++) {
      uint32_t t = lip.p[q];
      lip.p[q] = lip.p[lip.n - 1 - q];
      lip.p[lip.n - 1 - q] = t;
    }
  c->lips[c->nlips++] = (nm_lip_t){.side = forward ? 1 : 2, .len = lip.n, .nodes = lip.p};
  lip.p = NULL;
  rc = 0;
out:
  free(lip.p);
  free(s);
  free(order);
  free(match);
  return rc;
}

/* Unit normal of triangle (p, q, r) (zero if degenerate). */
static void tri_normal(const ctx_t *c, uint32_t p, uint32_t q, uint32_t r, double nrm[3]) {
  double bp[3], bq[3], br[3], u[3], w[3];
  const double *P = pos(c, p, bp), *Q = pos(c, q, bq), *R = pos(c, r, br);
  v3_sub(u, Q, P);
  v3_sub(w, R, P);
  v3_cross(nrm, u, w);
  v3_normalize(nrm);
}

/* Step 5: slivers left by the strip (a chain running along the curve, fans
 * at its ends) are flipped away: an edge shared by two new triangles, one of
 * them with an angle below NM_SLIVER_DEG, is replaced by the other diagonal
 * of their quadrilateral when that raises the smaller angle of the pair and
 * neither new triangle turns over. The new edge has a curve node at one end
 * at least, so it cannot exist elsewhere in the mesh; it is checked against
 * the new triangles. */
static void flip_slivers(ctx_t *c) {
  uint32_t *T = c->tris.p;
  size_t nt = c->tris.n / 3;
  for (int pass = 0; pass < 8; pass++) {
    int flips = 0;
    for (size_t t1 = 0; t1 < nt; t1++) {
      uint32_t *f = T + 3 * t1;
      double q1 = min_angle(c, f[0], f[1], f[2]);
      if (q1 >= NM_SLIVER_DEG) continue;
      for (int e = 0; e < 3; e++) {
        uint32_t p = f[e], q = f[(e + 1) % 3], r = f[(e + 2) % 3];
        size_t t2 = nt;
        int k2 = 0;
        for (size_t t = 0; t < nt && t2 == nt; t++)
          for (int k = 0; k < 3; k++)
            if (t != t1 && T[3 * t + k] == q && T[3 * t + (k + 1) % 3] == p) {
              t2 = t;
              k2 = k;
            }
        if (t2 == nt) continue;
        uint32_t s = T[3 * t2 + (k2 + 2) % 3];
        if (s == r || (r < c->n && s < c->n)) continue;
        int exists = 0;
        for (size_t t = 0; t < nt && !exists; t++) {
          const uint32_t *g = T + 3 * t;
          int hr = g[0] == r || g[1] == r || g[2] == r, hs = g[0] == s || g[1] == s || g[2] == s;
          exists = hr && hs;
        }
        if (exists) continue;
        double before = fmin(q1, min_angle(c, q, p, s));
        double after = fmin(min_angle(c, p, s, r), min_angle(c, s, q, r));
        double n1[3], n2[3], m1[3], m2[3];
        tri_normal(c, p, q, r, n1);
        tri_normal(c, q, p, s, n2);
        tri_normal(c, p, s, r, m1);
        tri_normal(c, s, q, r, m2);
        double ref[3] = {n1[0] + n2[0], n1[1] + n2[1], n1[2] + n2[2]};
        if (!(after > before + 1e-9) || v3_dot(m1, ref) <= 0 || v3_dot(m2, ref) <= 0) continue;
        uint32_t a[3] = {p, s, r}, b[3] = {s, q, r};
        memcpy(T + 3 * t1, a, sizeof a);
        memcpy(T + 3 * t2, b, sizeof b);
        flips++;
        break;
      }
    }
    if (!flips) break;
  }
}

/* Edges sorted by source, for walking. */
typedef struct edge_ix {
  uint32_t u, v;
  uint32_t used;
} edge_ix_t;

static int cmp_edge_u(const void *pa, const void *pb) {
  const edge_ix_t *a = pa, *b = pb;
  if (a->u != b->u) return a->u < b->u ? -1 : 1;
  return (a->v > b->v) - (a->v < b->v);
}
static int cmp_u32(const void *pa, const void *pb) {
  uint32_t a = *(const uint32_t *)pa, b = *(const uint32_t *)pb;
  return (a > b) - (a < b);
}

/* First unused edge leaving u, or -1. */
static long next_edge(edge_ix_t *e, size_t ne, uint32_t u) {
  size_t lo = 0, hi = ne;
  while (lo < hi) {
    size_t mid = (lo + hi) / 2;
    if (e[mid].u < u)
      lo = mid + 1;
    else
      hi = mid;
  }
  for (size_t k = lo; k < ne && e[k].u == u; k++)
    if (!e[k].used) return (long)k;
  return -1;
}

static size_t count_of(const uint32_t *sorted, size_t n, uint32_t x) {
  size_t lo = 0, hi = n;
  while (lo < hi) {
    size_t mid = (lo + hi) / 2;
    if (sorted[mid] < x)
      lo = mid + 1;
    else
      hi = mid;
  }
  size_t k = lo;
  while (k < n && sorted[k] == x) k++;
  return k - lo;
}

static size_t nearest_to(const ctx_t *c, const uint32_t *seq, size_t from, size_t to, const double *p) {
  size_t best = from;
  double bd = INFINITY;
  for (size_t i = from; i <= to; i++) {
    double d = v3_dist(c->x + 3 * (size_t)seq[i], p);
    if (d < bd) {
      bd = d;
      best = i;
    }
  }
  return best;
}

/* One boundary component: seq[0..len-1] (a loop repeats no node; an open
 * chain starts and ends on an existing boundary). */
static int do_component(ctx_t *c, uint32_t *seq, size_t len, int loop) {
  double P0[3], P3[3];
  bezier_eval(c->ctrl, 0, P0);
  bezier_eval(c->ctrl, 1, P3);
  if (len < 2 || c->total <= c->merge_tol) {
    c->open_left++;
    return 0;
  }
  if (loop) {
    /* Rotate so the loop starts at the node nearest P0, then split at the
     * node nearest P3: two sides sharing both end nodes. */
    size_t s0 = nearest_to(c, seq, 0, len - 1, P0);
    uint32_t *rot = malloc((len + 1) * sizeof *rot);
    if (!rot) return -1;
    for (size_t i = 0; i < len; i++) rot[i] = seq[(s0 + i) % len];
    rot[len] = rot[0];
    size_t s3 = nearest_to(c, rot, 1, len - 1, P3);
    uint32_t e0, e3;
    int rc = -1;
    if (new_node(c, 0, &e0) == 0 && new_node(c, 1, &e3) == 0 && do_side(c, rot, s3 + 1, 0, 1, e0, e3) == 0 &&
        do_side(c, rot + s3, len + 1 - s3, 1, 0, e3, e0) == 0)
      rc = 0;
    free(rot);
    return rc;
  }
  double a_s = bezier_nearest(c->ctrl, c->x + 3 * (size_t)seq[0], NM_NEAREST_SAMPLES, NULL);
  double a_e = bezier_nearest(c->ctrl, c->x + 3 * (size_t)seq[len - 1], NM_NEAREST_SAMPLES, NULL);
  if (fabs(a_e - a_s) >= 0.5 || len < 3) {
    /* One side from one boundary to the other. Its lip ends where the chain
     * ends project on the curve (not at the curve's ends: the chain may
     * border only part of the incision, e.g. where it crosses an earlier
     * wound); a lip shorter than merge_tol is one node. */
    uint32_t e_start, e_end;
    if (fabs(arc_of(c, a_e) - arc_of(c, a_s)) < c->merge_tol) {
      if (new_node(c, 0.5 * (a_s + a_e), &e_start)) return -1;
      return do_side(c, seq, len, a_s, a_e, e_start, e_start);
    }
    if (new_node(c, a_s, &e_start) || new_node(c, a_e, &e_end)) return -1;
    return do_side(c, seq, len, a_s, a_e, e_start, e_end);
  }
  /* Both ends near the same curve end (the incision starts at a boundary and
   * ends inside): split at the node nearest the far end, which is shared. */
  int near0 = a_s < 0.5;
  double a_far = near0 ? 1 : 0;
  size_t m = nearest_to(c, seq, 1, len - 2, near0 ? P3 : P0);
  uint32_t e_near_1, e_far, e_near_2;
  if (new_node(c, a_s, &e_near_1) || new_node(c, a_far, &e_far) || new_node(c, a_e, &e_near_2)) return -1;
  if (do_side(c, seq, m + 1, a_s, a_far, e_near_1, e_far)) return -1;
  return do_side(c, seq + m, len - m, a_far, a_e, e_far, e_near_2);
}

int node_match(size_t n, const double *x, size_t nedges, const uint32_t *edges, const double ctrl[4][3],
               double merge_tol, nm_result_t *out, verr_t *err) {
  memset(out, 0, sizeof *out);
  for (size_t k = 0; k < 2 * nedges; k++)
    if (edges[k] >= n) return verr_set(err, "node matching: hole edge %zu names node %u of %zu", k / 2, edges[k], n);
  ctx_t c = {.n = n, .x = x, .ctrl = ctrl, .merge_tol = merge_tol};
  double prev[3], cur[3];
  bezier_eval(ctrl, 0, prev);
  for (int i = 1; i <= NM_TABLE; i++) {
    bezier_eval(ctrl, (double)i / NM_TABLE, cur);
    c.s_tab[i] = c.s_tab[i - 1] + v3_dist(prev, cur);
    v3_copy(prev, cur);
  }
  c.total = c.s_tab[NM_TABLE];
  int rc = -1;
  edge_ix_t *e = malloc((nedges + 1) * sizeof *e);
  uint32_t *targets = malloc((nedges + 1) * sizeof *targets), *sources = malloc((nedges + 1) * sizeof *sources);
  u32vec_t seq = {0};
  if (!e || !targets || !sources) goto out;
  for (size_t k = 0; k < nedges; k++) {
    e[k] = (edge_ix_t){edges[2 * k], edges[2 * k + 1], 0};
    sources[k] = edges[2 * k];
    targets[k] = edges[2 * k + 1];
  }
  qsort(e, nedges, sizeof *e, cmp_edge_u);
  qsort(targets, nedges, sizeof *targets, cmp_u32);
  qsort(sources, nedges, sizeof *sources, cmp_u32);
  /* Open chains first: they start where more hole edges leave a node than
   * arrive (a node on an existing boundary), then the loops. */
  for (int pass = 0; pass < 2; pass++) {
    for (size_t k = 0; k < nedges; k++) {
      if (e[k].used) continue;
      uint32_t u = e[k].u;
      if (pass == 0 && count_of(sources, nedges, u) <= count_of(targets, nedges, u)) continue;
      seq.n = 0;
      if (u32_push(&seq, u)) goto out;
      long cur_e = (long)k;
      while (cur_e >= 0) {
        e[cur_e].used = 1;
        uint32_t v = e[cur_e].v;
        if (pass == 1 && v == u) break; /* the loop closed */
        if (u32_push(&seq, v)) goto out;
        cur_e = next_edge(e, nedges, v);
      }
      if (do_component(&c, seq.p, seq.n, pass == 1)) goto out;
    }
  }
  flip_slivers(&c);
  rc = 0;
out:
  free(e);
  free(targets);
  free(sources);
  free(seq.p);
  if (rc) {
    free(c.tris.p);
    free(c.match_node.p);
    free(c.match_to.p);
    free(c.a);
    for (size_t i = 0; i < c.nlips; i++) free(c.lips[i].nodes);
    free(c.lips);
    return verr_set(err, "node matching: out of memory");
  }
  out->nnew = c.nnew;
  out->a = c.a;
  out->ntris = c.tris.n / 3;
  out->tris = c.tris.p;
  out->nmatch = c.match_node.n;
  out->match_node = c.match_node.p;
  out->match_to = c.match_to.p;
  out->nlips = c.nlips;
  out->lips = c.lips;
  out->open_left = c.open_left;
  return 0;
}

void nm_result_free(nm_result_t *r) {
  free(r->a);
  free(r->tris);
  free(r->match_node);
  free(r->match_to);
  for (size_t i = 0; i < r->nlips; i++) free(r->lips[i].nodes);
  free(r->lips);
  memset(r, 0, sizeof *r);
}
