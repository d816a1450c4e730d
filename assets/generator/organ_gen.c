/* viscera-organ-gen OUTDIR: writes the built-in organ meshes (the source of truth
 * for the .obj files in assets/meshes) and prints a table of them.
 *
 * Units metres, z up; every mesh is centred in x and y with its lowest point at
 * z = 0. The closed organs are swept surfaces: a pole, rings, a pole (a
 * sphere's topology, T = 2V - 4), each ring a star-shaped curve in a plane
 * x = const with x strictly monotone from ring to ring: slices never meet, so
 * the smooth surface cannot pass through itself. The triangulation is even and
 * near-equilateral: rings sqrt(3)/2 edge lengths apart, each with as many
 * vertices as its length asks for, so the counts shrink by five or six a ring
 * toward each pole, as on a triangulated disc, and no vertex has a fan of thin
 * triangles: the poles have 5 to 7 neighbours, and the strips between rings
 * keep the other vertices to at most 7 (all have 5 to 7 in the meshes written
 * today). Even vertex spacing also suits the physics, which gives every vertex
 * the same mass. Shapes are smooth closed-form
 * functions, then scaled per axis to the target box: no randomness, the output
 * is the same on every run. gallbladder has 5,393 vertices, for the documents'
 * 10,782 triangles.
 *
 * tissue_block is the exception: an open, flat patch (45 vertices / 66 triangles
 * in 7 staggered rows of 6 and 7 vertices, 10 x 6 cm at z = 0, normals +z, so
 * its short sides zigzag). That is the simple tissue of the source documents; a
 * closed slab cannot have those counts (a closed sphere-like mesh has T = 2V - 4). */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "mesh.h"
#include "mesh_check.h"
#include "vmath.h"

#define PI 3.14159265358979323846

typedef void (*surface_fn)(double theta, double phi, double p[3]);

typedef struct organ {
  const char *name;  /* file stem */
  const char *about; /* first line of the OBJ */
  double size[3];    /* target bounding box, metres */
  size_t verts;      /* vertex count of a closed organ; 0 for the tissue patch */
  surface_fn surf;
} organ_t;

static double smoothstep(double a, double b, double x) {
  double t = (x - a) / (b - a);
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  return t * t * (3 - 2 * t);
}

/* Angular distance in [0, pi]. */
static double angle_dist(double a, double b) { return fabs(remainder(a - b, 2 * PI)); }

/* Each shape maps theta in [0, pi] (pole to pole along x) and phi (around) to a
 * point in units of the half length; the final size comes from scaling. */

/* Elongated, curved (concave on +y, the visceral side, with a shallow dent
 * there), larger at the upper pole. */
static void spleen_point(double th, double ph, double p[3]) {
  double x = -cos(th), s = sin(th);
  double env = pow(s, 0.75) * (1 + 0.18 * x);
  double dent = 1 - 0.3 * pow(fmax(0, cos(ph)), 3);
  p[0] = x;
  p[1] = 0.45 * env * cos(ph) * dent + 0.35 * x * x;
  p[2] = 0.28 * env * sin(ph) * dent;
}

/* Bean: bent toward -y, the medial side, where the hilum is a deep dent at
 * mid-length. */
static void kidney_point(double th, double ph, double p[3]) {
  double x = -cos(th), s = sin(th);
  double env = pow(s, 0.85);
  double d = angle_dist(ph, PI);
  double hilum = 1 - 0.5 * exp(-(x / 0.3) * (x / 0.3)) * exp(-(d / 0.75) * (d / 0.75));
  p[0] = x;
  p[1] = 0.55 * env * cos(ph) * hilum - 0.18 * x * x;
  p[2] = 0.32 * env * sin(ph) * hilum;
}

/* Pear: round fundus at +x, tapering to a narrow neck at -x that bends away. */
static void gallbladder_point(double th, double ph, double p[3]) {
  double x = -cos(th), s = sin(th), u = (1 + x) / 2;
  double r = 0.39 * pow(s, 0.6) * (0.28 + 0.72 * smoothstep(0, 0.75, u));
  double neck = (1 - u) * (1 - u) * (1 - u);
  p[0] = x;
  p[1] = r * cos(ph) + 0.12 * neck;
  p[2] = r * sin(ph) + 0.08 * neck;
}

/* Wedge: thick domed right lobe at -x, thinning to the left lobe tip, flat
 * underside rising toward the left, left lobe curling forward (-y). */
static void liver_point(double th, double ph, double p[3]) {
  double x = -cos(th), s = sin(th), u = (1 + x) / 2;
  double env = pow(s, 0.6);
  double a = 0.75 * (1 - 0.5 * u) * env, b = 0.5 * (1 - 0.75 * u) * env;
  double sz = sin(ph);
  p[0] = x;
  p[1] = a * cos(ph) - 0.25 * u * u;
  p[2] = b * sz * (sz < 0 ? 0.45 : 1) + 0.12 * u * u;
}

static const organ_t ORGANS[] = {
    {"tissue_block", "simple tissue patch, open, 10 x 6 cm", {0.10, 0.06, 0}, 0, NULL},
    {"spleen", "spleen, closed, 12 x 7 x 4 cm", {0.12, 0.07, 0.04}, 600, spleen_point},
    {"kidney", "kidney, closed, 11 x 6 x 3.5 cm", {0.11, 0.06, 0.035}, 2000, kidney_point},
    {"gallbladder", "gallbladder, closed, 9 x 3.5 x 3.5 cm", {0.09, 0.035, 0.035}, 5393, gallbladder_point},
    /* 23,522 vertices: the mesh size of the nearest-feature query benchmark. */
    {"liver_large", "liver, closed, 20 x 14 x 10 cm", {0.20, 0.14, 0.10}, 23522, liver_point},
};

/* Rows alternate 6 (even rows, offset by half a step) and 7 vertices; each pair
 * of rows is a zigzag strip of 6 + 5 triangles, counter-clockwise from above. */
static int build_tissue(mesh_t *m, verr_t *err) {
  enum { ROWS = 7, LONG = 7, SHORT = 6 };
  if (mesh_alloc(m, 4 * SHORT + 3 * LONG, 6 * (SHORT + SHORT - 1), err)) return -1;
  uint32_t start[ROWS];
  uint32_t v = 0;
  for (int r = 0; r < ROWS; r++) {
    int is_long = r % 2;
    start[r] = v;
    for (int j = 0; j < (is_long ? LONG : SHORT); j++, v++) {
      m->pos[3 * v] = (j + (is_long ? 0 : 0.5)) / (LONG - 1);
      m->pos[3 * v + 1] = (double)r / (ROWS - 1);
      m->pos[3 * v + 2] = 0;
    }
  }
  uint32_t *t = m->tris;
  for (int r = 0; r + 1 < ROWS; r++) {
    int long_below = r % 2;
    uint32_t L = start[long_below ? r : r + 1], S = start[long_below ? r + 1 : r];
    for (uint32_t j = 0; j < SHORT; j++) {
      uint32_t a[3] = {L + j, L + j + 1, S + j}, b[3] = {S + j, L + j + 1, L + j};
      memcpy(t, long_below ? a : b, sizeof a);
      t += 3;
    }
    for (uint32_t j = 0; j + 1 < SHORT; j++) {
      uint32_t a[3] = {S + j, L + j + 1, S + j + 1}, b[3] = {S + j, S + j + 1, L + j + 1};
      memcpy(t, long_below ? a : b, sizeof a);
      t += 3;
    }
  }
  return 0;
}

/* The poles' valence range (the vertex counts of the rings next to them); the
 * strips between rings give no vertex more than MAX_VALENCE edges while they
 * have the choice. */
enum { MIN_VALENCE = 5, MAX_VALENCE = 7 };
/* Planning resolution: steps in theta from pole to pole, samples around a ring. */
enum { MER_STEPS = 4096, RING_SAMPLES = 512 };
/* Where the rings crowd together the vertices do too, by this power of the
 * ratio of gaps (see ring_density): 0 would keep them evenly spaced around the
 * ring, 1 keep the triangles' proportions, at the price of higher pole valences
 * on a flattened end. */
static const double GAP_EXP = 0.5;

typedef struct sweep {
  const organ_t *o;
  double sc[3];  /* shape units to metres, per axis (place() makes the size exact) */
  int nrings;    /* rings between the poles */
  double *theta; /* per ring */
  int *count;    /* vertices per ring */
} sweep_t;

static void sweep_free(sweep_t *sw) {
  free(sw->theta);
  free(sw->count);
  sw->theta = NULL;
  sw->count = NULL;
}

/* A point of the shape in (approximate) metres. */
static void eval_m(const sweep_t *sw, double th, double ph, double p[3]) {
  sw->o->surf(th < 0 ? 0 : th > PI ? PI : th, ph, p);
  for (int k = 0; k < 3; k++) p[k] *= sw->sc[k];
}

static double dist_sc(const double *a, const double *b, const double sc[3]) {
  double d[3] = {(a[0] - b[0]) * sc[0], (a[1] - b[1]) * sc[1], (a[2] - b[2]) * sc[2]};
  return v3_norm(d);
}

/* Cumulative vertex density around ring k into cl[0..ns] (cl[m] at phi =
 * 2 pi m / ns): arc length, each piece weighted by (mean gap / gap)^GAP_EXP,
 * the gap being the distance across the ring, along the surface, to the
 * curves a quarter of the way to the neighbouring rings. So the vertices
 * crowd where the rings do, as on the flat side of a flattened end, and the
 * triangles there keep more of their proportions. cl[ns] / h is the number of
 * vertices the ring wants for edge length h. Returns -1 out of memory. */
static int ring_density(const sweep_t *sw, int k, int ns, double *cl) {
  double *p = malloc(3 * (size_t)ns * sizeof *p), *gap = malloc((size_t)ns * sizeof *gap);
  if (!p || !gap) {
    free(p);
    free(gap);
    return -1;
  }
  double th = sw->theta[k];
  double eps = 0.25 * fmin(th - (k ? sw->theta[k - 1] : 0), (k + 1 < sw->nrings ? sw->theta[k + 1] : PI) - th);
  for (int m = 0; m < ns; m++) eval_m(sw, th, 2 * PI * m / ns, p + 3 * m);
  for (int m = 0; m < ns; m++) {
    double lo[3], hi[3], tng[3], d[3];
    eval_m(sw, th - eps, 2 * PI * m / ns, lo);
    eval_m(sw, th + eps, 2 * PI * m / ns, hi);
    v3_sub(tng, p + 3 * ((m + 1) % ns), p + 3 * ((m + ns - 1) % ns));
    v3_normalize(tng);
    v3_sub(d, hi, lo);
    v3_axpy(d, tng, -v3_dot(d, tng));
    gap[m] = v3_norm(d);
  }
  double len = 0, wgap = 0;
  for (int m = 0; m < ns; m++) {
    double c = v3_dist(p + 3 * m, p + 3 * ((m + 1) % ns));
    len += c;
    wgap += c * 0.5 * (gap[m] + gap[(m + 1) % ns]);
  }
  cl[0] = 0;
  for (int m = 0; m < ns; m++) {
    int m1 = (m + 1) % ns;
    cl[m + 1] = cl[m] + v3_dist(p + 3 * m, p + 3 * m1) * pow(wgap / len / (0.5 * (gap[m] + gap[m1])), GAP_EXP);
  }
  free(p);
  free(gap);
  return 0;
}

/* Ring vertex counts for edge length h from the ring densities; returns the
 * mesh's vertex count. The rings next to the poles give the poles' valences. */
static size_t set_counts(sweep_t *sw, const double *dens, double h) {
  size_t v = 2;
  for (int k = 0; k < sw->nrings; k++) {
    long n = lround(dens[k] / h), lo = 3, hi = LONG_MAX;
    if (k == 0 || k == sw->nrings - 1) lo = MIN_VALENCE, hi = MAX_VALENCE;
    sw->count[k] = (int)(n < lo ? lo : n > hi ? hi : n);
    v += (size_t)sw->count[k];
  }
  return v;
}

/* Plans the rings of an even, near-equilateral triangulation with o->verts
 * vertices: the edge length h0 that gives equilateral triangles that many
 * vertices over the area; rings sqrt(3)/2 h0 apart in meridian arc length
 * (averaged around the rings); then the edge length whose ring counts
 * (ring_density / h) add up to o->verts, found by bisection. */
static int plan_sweep(const organ_t *o, sweep_t *sw, verr_t *err) {
  memset(sw, 0, sizeof *sw);
  sw->o = o;
  /* Scale factors from a sampling of the shape. */
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int i = 0; i <= MER_STEPS; i++)
    for (int m = 0; m < RING_SAMPLES; m++) {
      double p[3];
      o->surf(PI * i / MER_STEPS, 2 * PI * m / RING_SAMPLES, p);
      for (int k = 0; k < 3; k++) {
        lo[k] = fmin(lo[k], p[k]);
        hi[k] = fmax(hi[k], p[k]);
      }
    }
  for (int k = 0; k < 3; k++) sw->sc[k] = o->size[k] / (hi[k] - lo[k]);
  /* Mean meridian arc length s from the first pole, and the area. */
  double *s = malloc((MER_STEPS + 1) * sizeof *s), *dens = NULL;
  double *prev = malloc(3 * RING_SAMPLES * sizeof *prev), *cur = malloc(3 * RING_SAMPLES * sizeof *cur);
  double cl[RING_SAMPLES + 1];
  int rc = -1;
  if (!s || !prev || !cur) goto out;
  double area = 0, per_prev = 0;
  for (int m = 0; m < RING_SAMPLES; m++) eval_m(sw, 0, 2 * PI * m / RING_SAMPLES, prev + 3 * m);
  s[0] = 0;
  for (int i = 1; i <= MER_STEPS; i++) {
    double per = 0, ds = 0;
    for (int m = 0; m < RING_SAMPLES; m++) eval_m(sw, PI * i / MER_STEPS, 2 * PI * m / RING_SAMPLES, cur + 3 * m);
    for (int m = 0; m < RING_SAMPLES; m++) {
      per += v3_dist(cur + 3 * m, cur + 3 * ((m + 1) % RING_SAMPLES));
      ds += v3_dist(cur + 3 * m, prev + 3 * m) / RING_SAMPLES;
    }
    s[i] = s[i - 1] + ds;
    area += 0.5 * (per_prev + per) * ds;
    per_prev = per;
    double *t = prev;
    prev = cur;
    cur = t;
  }
  double h0 = sqrt(2 * area / (sqrt(3.0) * (double)o->verts));
  long nr = lround(s[MER_STEPS] / (h0 * sqrt(3.0) / 2)) - 1;
  sw->nrings = nr < 1 ? 1 : (int)nr;
  sw->theta = malloc((size_t)sw->nrings * sizeof *sw->theta);
  sw->count = malloc((size_t)sw->nrings * sizeof *sw->count);
  dens = malloc((size_t)sw->nrings * sizeof *dens);
  if (!sw->theta || !sw->count || !dens) goto out;
  for (int k = 0, i = 1; k < sw->nrings; k++) {
    double target = s[MER_STEPS] * (k + 1) / (sw->nrings + 1);
    while (s[i] < target) i++;
    sw->theta[k] = PI * (i - 1 + (target - s[i - 1]) / (s[i] - s[i - 1])) / MER_STEPS;
  }
  for (int k = 0; k < sw->nrings; k++) {
    if (ring_density(sw, k, RING_SAMPLES, cl)) goto out;
    dens[k] = cl[RING_SAMPLES];
  }
  /* Fewer vertices as the edge length grows: keep v(hlo) >= verts > v(hhi). */
  double hlo = h0 / 4, hhi = 4 * h0;
  for (int it = 0; it < 100; it++) {
    double mid = 0.5 * (hlo + hhi);
    if (set_counts(sw, dens, mid) >= o->verts)
      hlo = mid;
    else
      hhi = mid;
  }
  double vlo = (double)set_counts(sw, dens, hlo), vhi = (double)set_counts(sw, dens, hhi);
  set_counts(sw, dens, fabs(vhi - (double)o->verts) < fabs(vlo - (double)o->verts) ? hhi : hlo);
  rc = 0;
out:
  free(s);
  free(dens);
  free(prev);
  free(cur);
  if (rc) {
    sweep_free(sw);
    verr_set(err, "%s: out of memory planning the mesh", o->name);
  }
  return rc;
}

/* Joins ring a (na vertices from index a) to the next ring b (nb from b) with
 * na + nb triangles, walking both rings from a's first vertex and the nearest
 * of b's, each time closing the triangle whose new edge is shorter, unless
 * that edge would take a vertex of a above MAX_VALENCE edges or one of b above
 * MAX_VALENCE - b_reserve (b_reserve: the fewest the next strip will add).
 * deg holds each vertex's edges so far. Returns the end of the triangles. */
static uint32_t *zip_rings(const mesh_t *m, const double sc[3], uint32_t a, uint32_t na, uint32_t b, uint32_t nb,
                           int b_reserve, int *deg, uint32_t *t) {
  uint32_t js = 0;
  double best = INFINITY;
  for (uint32_t j = 0; j < nb; j++) {
    double d = dist_sc(m->pos + 3 * (size_t)a, m->pos + 3 * (size_t)(b + j), sc);
    if (d < best) {
      best = d;
      js = j;
    }
  }
#define A(k) (a + (k) % na)
#define B(k) (b + ((k) + js) % nb)
#define POS(v) (m->pos + 3 * (size_t)(v))
  const int cap_b = MAX_VALENCE - b_reserve;
  uint32_t i = 0, j = 0;
  deg[A(0)]++;
  deg[B(0)]++;
  while (i < na || j < nb) {
    int adv_a;
    if (i == na || j == nb)
      adv_a = i < na;
    else {
      /* The new edge is a(i+1)-b(j) or a(i)-b(j+1). Once a ring is done, the
       * rest of the other all joins its first vertex. */
      int ok_a = i + 1 == na ? deg[A(0)] + (int)(nb - j) - (j == 0) <= MAX_VALENCE && (j == 0 || deg[B(j)] < cap_b)
                             : deg[B(j)] < cap_b;
      int ok_b = j + 1 == nb ? deg[B(0)] + (int)(na - i) - (i == 0) <= cap_b && (i == 0 || deg[A(i)] < MAX_VALENCE)
                             : deg[A(i)] < MAX_VALENCE && deg[B(j + 1)] < cap_b;
      if (ok_a != ok_b)
        adv_a = ok_a;
      else
        adv_a = dist_sc(POS(A(i + 1)), POS(B(j)), sc) <= dist_sc(POS(A(i)), POS(B(j + 1)), sc);
    }
    uint32_t q[3] = {A(i), adv_a ? A(i + 1) : B(j + 1), B(j)};
    memcpy(t, q, sizeof q);
    t += 3;
    if (adv_a)
      i++;
    else
      j++;
    if (!(i == na && j % nb == 0) && !(j == nb && i % na == 0)) { /* not the first edge again */
      deg[A(i)]++;
      deg[B(j)]++;
    }
  }
#undef A
#undef B
#undef POS
  return t;
}

/* Pole, rings, pole; the whole mesh is flipped at the end if the sweep
 * direction made it inward. */
static int build_sweep(mesh_t *m, const organ_t *o, verr_t *err) {
  sweep_t sw;
  if (plan_sweep(o, &sw, err)) return -1;
  size_t nv = 2;
  int maxn = 0;
  for (int k = 0; k < sw.nrings; k++) {
    nv += (size_t)sw.count[k];
    maxn = sw.count[k] > maxn ? sw.count[k] : maxn;
  }
  int ns = 8 * maxn > RING_SAMPLES ? 8 * maxn : RING_SAMPLES;
  double *cl = malloc(((size_t)ns + 1) * sizeof *cl);
  uint32_t *start = malloc((size_t)sw.nrings * sizeof *start);
  int *deg = calloc(nv, sizeof *deg);
  int rc = -1;
  if (!cl || !start || !deg) {
    verr_set(err, "%s: out of memory", o->name);
    goto out;
  }
  if (mesh_alloc(m, nv, 2 * nv - 4, err)) goto out;
  const uint32_t last = (uint32_t)nv - 1;
  o->surf(0, 0, m->pos);
  o->surf(PI, 0, m->pos + 3 * (size_t)last);
  uint32_t v = 1;
  for (int k = 0; k < sw.nrings; k++) {
    /* Equal steps of the density, odd rings offset by half a step. */
    if (ring_density(&sw, k, ns, cl)) {
      mesh_free(m);
      verr_set(err, "%s: out of memory", o->name);
      goto out;
    }
    int n = sw.count[k], seg = 0;
    start[k] = v;
    for (int j = 0; j < n; j++, v++) {
      double target = cl[ns] * (j + 0.5 * (k % 2)) / n;
      while (seg + 1 < ns && cl[seg + 1] <= target) seg++;
      double f = (target - cl[seg]) / (cl[seg + 1] - cl[seg]);
      o->surf(sw.theta[k], 2 * PI * (seg + f) / ns, m->pos + 3 * (size_t)v);
    }
  }
  /* Fans to the poles; strips between the rings, whose vertices start with
   * the two edges along their ring. */
  for (uint32_t q = 1; q < last; q++) deg[q] = 2;
  uint32_t *t = m->tris;
  uint32_t n0 = (uint32_t)sw.count[0], nl = (uint32_t)sw.count[sw.nrings - 1], sl = start[sw.nrings - 1];
  for (uint32_t j = 0; j < n0; j++) {
    uint32_t first[3] = {0, start[0] + (j + 1) % n0, start[0] + j};
    memcpy(t, first, sizeof first);
    t += 3;
    deg[start[0] + j]++;
  }
  for (int k = 0; k + 1 < sw.nrings; k++) {
    /* Next, each vertex of ring k + 1 meets at least this many of ring k + 2 (or the pole). */
    int reserve = k + 2 < sw.nrings ? 1 + sw.count[k + 2] / sw.count[k + 1] : 1;
    t = zip_rings(m, sw.sc, start[k], (uint32_t)sw.count[k], start[k + 1], (uint32_t)sw.count[k + 1], reserve, deg, t);
  }
  for (uint32_t j = 0; j < nl; j++) {
    uint32_t end[3] = {last, sl + j, sl + (j + 1) % nl};
    memcpy(t, end, sizeof end);
    t += 3;
  }
  if (mesh_signed_volume(m) < 0)
    for (size_t k = 0; k < m->ntris; k++) {
      uint32_t x = m->tris[3 * k + 1];
      m->tris[3 * k + 1] = m->tris[3 * k + 2];
      m->tris[3 * k + 2] = x;
    }
  rc = 0;
out:
  free(cl);
  free(start);
  free(deg);
  sweep_free(&sw);
  return rc;
}

/* Scales each axis to the target size (positive factors keep the surface
 * embedded and its orientation), puts the lowest point at z = 0 centred in x,y,
 * and rounds to float: the importer keeps no more, so the file claims no
 * precision the server will not see. */
static void place(mesh_t *m, const double size[3]) {
  double lo[3], hi[3];
  mesh_bounds(m, lo, hi);
  for (size_t v = 0; v < m->nverts; v++)
    for (int k = 0; k < 3; k++) {
      double ext = hi[k] - lo[k];
      double s = ext > 0 ? size[k] / ext : 1;
      double x = (m->pos[3 * v + k] - (k == 2 ? lo[k] : 0.5 * (lo[k] + hi[k]))) * s;
      m->pos[3 * v + k] = (float)x;
    }
}

/* Numbers vertices by first use in the triangle list, the order mesh_import
 * produces, so importing the file gives back this mesh vertex for vertex. */
static int renumber_first_use(mesh_t *m, verr_t *err) {
  uint32_t *id = malloc(m->nverts * sizeof *id);
  double *pos = malloc(3 * m->nverts * sizeof *pos);
  if (!id || !pos) {
    free(id);
    free(pos);
    return verr_set(err, "out of memory renumbering %zu vertices", m->nverts);
  }
  memset(id, 0xff, m->nverts * sizeof *id);
  uint32_t n = 0;
  for (size_t c = 0; c < 3 * m->ntris; c++) {
    uint32_t v = m->tris[c];
    if (id[v] == UINT32_MAX) {
      id[v] = n;
      memcpy(pos + 3 * (size_t)n, m->pos + 3 * (size_t)v, 3 * sizeof *pos);
      n++;
    }
    m->tris[c] = id[v];
  }
  free(m->pos);
  free(id);
  m->pos = pos;
  if (n != m->nverts) return verr_set(err, "%zu vertices are unused", m->nverts - n);
  return 0;
}

/* The generator refuses to write a mesh its own checker finds fault with. */
static int verify(const organ_t *o, const mesh_t *m, mesh_report_t *r, verr_t *err) {
  if (mesh_check(m, r)) return verr_set(err, "%s: out of memory checking the mesh", o->name);
  int open_patch = o->surf == NULL;
  if (r->nonmanifold_edges || r->inconsistent_edges || r->degenerate_faces || r->duplicate_vertices ||
      r->unreferenced_vertices || r->components != 1 || r->nonfinite_vertices || r->bad_index_faces)
    return verr_set(err, "%s: generated mesh has problems (run viscera-asset info on it)", o->name);
  if (!open_patch && (!r->closed || !(r->volume > 0)))
    return verr_set(err, "%s: generated mesh is not closed with positive volume", o->name);
  if (open_patch && r->boundary_edges == 0) return verr_set(err, "%s: patch unexpectedly closed", o->name);
  return 0;
}

static int make_organ(const organ_t *o, const char *dir, mesh_report_t *r, verr_t *err) {
  mesh_t m;
  if ((o->surf ? build_sweep(&m, o, err) : build_tissue(&m, err))) return -1;
  place(&m, o->size);
  char path[4096];
  int rc = renumber_first_use(&m, err);
  if (!rc) rc = verify(o, &m, r, err);
  if (!rc && snprintf(path, sizeof path, "%s/%s.obj", dir, o->name) >= (int)sizeof path)
    rc = verr_set(err, "%s: output path too long", dir);
  if (!rc) {
    char comment[256];
    snprintf(comment, sizeof comment, "%s; metres, z up; written by viscera-organ-gen, do not edit", o->about);
    rc = mesh_write_obj(&m, path, comment, err);
  }
  mesh_free(&m);
  return rc;
}

static void usage(FILE *f) {
  fprintf(f, "usage: viscera-organ-gen OUTDIR\n"
             "       viscera-organ-gen --help | --version\n"
             "Writes tissue_block, spleen, kidney, gallbladder and liver_large (.obj, metres, z up)\n"
             "into OUTDIR (created if missing) and prints their sizes. The repository copies live\n"
             "in assets/meshes/; regenerate them with this tool rather than editing them.\n"
             "Exit status: 0 written, 1 cannot write OUTDIR, 2 usage error.\n");
}

int main(int argc, char **argv) {
  if (argc == 2 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"))) {
    usage(stdout);
    return 0;
  }
  if (argc == 2 && !strcmp(argv[1], "--version")) {
    printf("viscera-organ-gen %s\n", cli_version());
    return 0;
  }
  if (argc != 2 || argv[1][0] == '-') {
    usage(stderr);
    return 2;
  }
  const char *dir = argv[1];
  if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
    fprintf(stderr, "viscera-organ-gen: %s: cannot create directory: %s\n", dir, strerror(errno));
    return 1;
  }
  printf("%-14s %9s %10s   %s\n", "name", "vertices", "triangles", "size (m)");
  for (size_t i = 0; i < sizeof ORGANS / sizeof ORGANS[0]; i++) {
    mesh_report_t r;
    verr_t err = {{0}};
    if (make_organ(&ORGANS[i], dir, &r, &err)) {
      fprintf(stderr, "viscera-organ-gen: %s\n", err.msg);
      return 1;
    }
    printf("%-14s %9zu %10zu   %.4f x %.4f x %.4f%s\n", ORGANS[i].name, r.vertices, r.triangles, r.size[0], r.size[1],
           r.size[2], r.closed ? "" : "  (open patch)");
  }
  return 0;
}
