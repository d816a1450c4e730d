/* SPDX-License-Identifier: Apache-2.0 */
/* bench_collision: cost of the collision queries (docs/numerics.md §7: nearest
 * feature on the 23,522-vertex liver <= 1 us median; the thesis of docs/methods.md B
 * reports 1.35 us).
 *
 * For each generated organ: AABB tree build and refit (at rest, and with
 * every vertex moved), node grid build and rebuild. On the liver: the nearest surface point to random points near the
 * surface (a random point of a random triangle moved along its normal by up
 * to 0, 2 or 5 mm; the mean edge is 1.8 mm), and along a sliding path like a
 * haptic proxy's, per query median and p99, also after a deformation and
 * refit; the first entering hit along random 2 cm segments through the
 * surface; the nearest node on the grid against a linear scan. For each
 * organ: proxy_update per haptic step with the tree against the scan over
 * triangles (the proxy's own culled scan), on a scripted press-and-slide path.
 * Each query is timed on its own with CLOCK_MONOTONIC; the timer's own cost
 * (back-to-back reads) is printed and not subtracted; the batch mean (one
 * timer around all queries) is printed beside it. One core, this build's flags.
 * usage: bench_collision ASSETS_DIR [OUT.csv] [--quick] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "collision/aabb_tree.h"
#include "collision/node_grid.h"
#include "haptics/proxy.h"
#include "mesh.h"
#include "test_assets.h"
#include "test_rng.h"
#include "vmath.h"
#include "vstats.h"
#include "vtime.h"

static const char *ORGANS[] = {"tissue_block", "spleen", "kidney", "gallbladder", "liver_large"};

static uint64_t rng_state = 0x243f6a8885a308d3ull;
static double urand(void) { return test_rng_uniform(&rng_state); }

static FILE *csv;

static void row(const char *organ, const char *what, double *samples_us, size_t n, double batch_mean_us) {
  vstats_summary_t s = vstats_summarise(samples_us, n);
  printf("  %-12s %-34s %9zu %10.3f %10.3f %10.3f %10.3f\n", organ, what, s.n, s.median, s.p99, s.max, batch_mean_us);
  if (csv) fprintf(csv, "%s,%s,%zu,%.4f,%.4f,%.4f,%.4f\n", organ, what, s.n, s.median, s.p99, s.max, batch_mean_us);
}

static void header(const char *title) {
  printf("\n%s\n  %-12s %-34s %9s %10s %10s %10s %10s\n", title, "organ", "measure", "n", "median_us", "p99_us",
         "max_us", "batch_us");
}

/* A point of a random triangle, moved along its normal by up to +-offset. */
static void near_surface(const double *x, const uint32_t *tris, size_t ntris, double offset, double q[3],
                         double nrm[3]) {
  size_t t = (size_t)(urand() * (double)ntris);
  const double *a = x + 3 * tris[3 * t], *b = x + 3 * tris[3 * t + 1], *c = x + 3 * tris[3 * t + 2];
  double u = urand(), v = urand(), e1[3], e2[3], n[3];
  if (u + v > 1) {
    u = 1 - u;
    v = 1 - v;
  }
  v3_sub(e1, b, a);
  v3_sub(e2, c, a);
  v3_cross(n, e1, e2);
  v3_normalize(n);
  double h = offset * (2 * urand() - 1);
  for (int k = 0; k < 3; k++) q[k] = a[k] + u * e1[k] + v * e2[k] + h * n[k];
  if (nrm) v3_copy(nrm, n);
}

static void deform(const double *rest, double *x, size_t n, double amp) {
  for (size_t i = 0; i < n; i++) {
    const double *p = rest + 3 * i;
    x[3 * i] = p[0] + amp * sin(31 * p[1]);
    x[3 * i + 1] = p[1] + amp * sin(23 * p[2] + 1);
    x[3 * i + 2] = p[2] + amp * sin(37 * p[0] + 2) * cos(19 * p[1]);
  }
}

static double max_edge_of(const mesh_t *m) {
  double e = 0;
  for (size_t t = 0; t < m->ntris; t++)
    for (int j = 0; j < 3; j++)
      e = fmax(e, v3_dist(m->pos + 3 * m->tris[3 * t + (size_t)j], m->pos + 3 * m->tris[3 * t + (size_t)(j + 1) % 3]));
  return e;
}

static volatile double sink;

/* Nearest-point queries over a prepared list: per-query samples and a batch mean. */
static void bench_nearest(const char *organ, const char *what, const aabb_tree_t *t, const double *q, size_t nq,
                          double *us) {
  aabb_nearest_t r;
  for (size_t i = 0; i < nq / 10; i++) aabb_tree_nearest(t, q + 3 * i, INFINITY, &r); /* warm the caches */
  for (size_t i = 0; i < nq; i++) {
    uint64_t t0 = vtime_mono_ns();
    aabb_tree_nearest(t, q + 3 * i, INFINITY, &r);
    uint64_t t1 = vtime_mono_ns();
    sink += r.dist2;
    us[i] = (double)(t1 - t0) * 1e-3;
  }
  uint64_t b0 = vtime_mono_ns();
  for (size_t i = 0; i < nq; i++) {
    aabb_tree_nearest(t, q + 3 * i, INFINITY, &r);
    sink += r.dist2;
  }
  double batch = (double)(vtime_mono_ns() - b0) * 1e-3 / (double)nq;
  row(organ, what, us, nq, batch);
}

static void random_queries(const mesh_t *m, const double *x, double offset, double *q, size_t nq) {
  for (size_t i = 0; i < nq; i++) near_surface(x, m->tris, m->ntris, offset, q + 3 * i, NULL);
}

/* What a haptic proxy asks: each query 0.05 mm further along the surface
 * from the last answer, bobbing up to 1 mm off it (a 1 kHz loop sliding at
 * 5 cm/s), restarting at a random point every 2000 steps. */
static void path_queries(const mesh_t *m, const aabb_tree_t *t, double *q, size_t nq) {
  double p[3] = {0, 0, 0}, n[3] = {0, 0, 1}, dir[3] = {1, 0, 0};
  for (size_t i = 0; i < nq; i++) {
    if (i % 2000 == 0) {
      double r[3] = {urand() - 0.5, urand() - 0.5, urand() - 0.5};
      near_surface(m->pos, m->tris, m->ntris, 0, p, n);
      v3_cross(dir, n, r);
      v3_normalize(dir);
    }
    double h = 0.001 * sin(0.01 * (double)i);
    for (int k = 0; k < 3; k++) q[3 * i + (size_t)k] = p[k] + h * n[k];
    aabb_nearest_t r;
    aabb_tree_nearest(t, q + 3 * i, INFINITY, &r);
    /* Step from the answer along the current direction, kept tangent to the new triangle. */
    const uint32_t *tv = m->tris + 3 * (size_t)r.tri;
    double e1[3], e2[3];
    v3_sub(e1, m->pos + 3 * tv[1], m->pos + 3 * tv[0]);
    v3_sub(e2, m->pos + 3 * tv[2], m->pos + 3 * tv[0]);
    v3_cross(n, e1, e2);
    v3_normalize(n);
    v3_axpy(dir, n, -v3_dot(dir, n));
    v3_normalize(dir);
    v3_copy(p, r.point);
    v3_axpy(p, dir, 5e-5);
  }
}

static void scan_nearest(const double *x, const uint32_t *tris, size_t ntris, const double q[3]) {
  double best = INFINITY;
  for (size_t t = 0; t < ntris; t++) {
    double cp[3], bary[3], d[3];
    tri_closest_point(q, x + 3 * tris[3 * t], x + 3 * tris[3 * t + 1], x + 3 * tris[3 * t + 2], cp, bary);
    v3_sub(d, cp, q);
    best = fmin(best, v3_dot(d, d));
  }
  sink += best;
}

/* Proxy cost per haptic step on a scripted path: press 1 cm in along a
 * vertex normal, slide 2 cm, leave; repeated over random vertices. */
static void bench_proxy(const char *organ, const mesh_t *m, aabb_tree_t *tree, int presses, double *us_tree,
                        double *us_scan, size_t *nsamples) {
  double *nrm = calloc(3 * m->nverts, sizeof *nrm);
  for (size_t t = 0; t < m->ntris; t++) {
    const uint32_t *v = m->tris + 3 * t;
    double e1[3], e2[3], n[3];
    v3_sub(e1, m->pos + 3 * v[1], m->pos + 3 * v[0]);
    v3_sub(e2, m->pos + 3 * v[2], m->pos + 3 * v[0]);
    v3_cross(n, e1, e2);
    for (int j = 0; j < 3; j++) v3_axpy(nrm + 3 * v[j], n, 1.0);
  }
  proxy_surface_t scan = {
      .x = m->pos, .tris = m->tris, .ntris = m->ntris, .max_edge = 3 * max_edge_of(m), .x_rest = m->pos};
  proxy_surface_t withtree = scan;
  withtree.tree = tree;
  size_t n = 0;
  uint64_t t_tree = 0, t_scan = 0;
  size_t contact = 0;
  for (int pr = 0; pr < presses; pr++) {
    size_t v = (size_t)(urand() * (double)m->nverts);
    double nv[3], side[3], r[3] = {urand() - 0.5, urand() - 0.5, urand() - 0.5};
    v3_copy(nv, nrm + 3 * v);
    v3_normalize(nv);
    v3_cross(side, nv, r);
    v3_normalize(side);
    proxy_t pa, pb;
    proxy_reset(&pa);
    proxy_reset(&pb);
    for (int s = 0; s < 100; s++) {
      double out = s < 30 ? 0.02 - 0.03 * s / 29.0 : s < 80 ? -0.01 : -0.01 + 0.03 * (s - 79) / 20.0;
      double slide = s < 30 ? 0 : s < 80 ? 0.02 * (s - 30) / 49.0 : 0.02;
      double dev[3], f[3];
      for (int k = 0; k < 3; k++) dev[k] = m->pos[3 * v + (size_t)k] + out * nv[k] + slide * side[k];
      uint64_t t0 = vtime_mono_ns();
      int c = proxy_update(&pa, dev, &withtree, 1, 300, 4, f);
      uint64_t t1 = vtime_mono_ns();
      proxy_update(&pb, dev, &scan, 1, 300, 4, f);
      uint64_t t2 = vtime_mono_ns();
      us_tree[n] = (double)(t1 - t0) * 1e-3;
      us_scan[n] = (double)(t2 - t1) * 1e-3;
      t_tree += t1 - t0;
      t_scan += t2 - t1;
      contact += (size_t)c;
      n++;
    }
  }
  *nsamples = n;
  char what[64];
  snprintf(what, sizeof what, "proxy_update, tree (%.0f%% contact)", 100.0 * (double)contact / (double)n);
  row(organ, what, us_tree, n, (double)t_tree * 1e-3 / (double)n);
  row(organ, "proxy_update, scan", us_scan, n, (double)t_scan * 1e-3 / (double)n);
  free(nrm);
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: bench_collision ASSETS_DIR [OUT.csv] [--quick]\n");
    return 2;
  }
  const char *csv_path = NULL;
  int quick = 0;
  for (int i = 2; i < argc; i++) {
    if (!strcmp(argv[i], "--quick"))
      quick = 1;
    else
      csv_path = argv[i];
  }
  csv = csv_path ? fopen(csv_path, "w") : NULL;
  if (csv_path && !csv) {
    fprintf(stderr, "bench_collision: cannot write %s\n", csv_path);
    return 1;
  }
  if (csv) fprintf(csv, "organ,measure,n,median_us,p99_us,max_us,batch_mean_us\n");
  size_t norgans = sizeof ORGANS / sizeof ORGANS[0];
  mesh_t meshes[sizeof ORGANS / sizeof ORGANS[0]];
  test_assets_dir_set(argv[1]);
  for (size_t oi = 0; oi < norgans; oi++)
    if (test_organ_load(ORGANS[oi], &meshes[oi])) return 1;
  /* The timer's own cost, for reading the per-query figures. */
  double timer[1000];
  for (int i = 0; i < 1000; i++) {
    uint64_t a = vtime_mono_ns(), b = vtime_mono_ns();
    timer[i] = (double)(b - a) * 1e-3;
  }
  vstats_summary_t ts = vstats_summarise(timer, 1000);
  printf("bench_collision%s: per-query times include one timer read pair (median %.3f us)\n", quick ? " --quick" : "",
         ts.median);

  header("build and update (per call)");
  int reps = quick ? 5 : 30;
  double samples[64];
  for (size_t oi = 0; oi < norgans; oi++) {
    mesh_t *m = &meshes[oi];
    verr_t err;
    aabb_tree_t t;
    for (int r = 0; r < reps; r++) {
      uint64_t t0 = vtime_mono_ns();
      aabb_tree_build(&t, m->pos, m->nverts, m->tris, m->ntris, &err);
      samples[r] = (double)(vtime_mono_ns() - t0) * 1e-3;
      if (r + 1 < reps) aabb_tree_destroy(&t);
    }
    char what[64];
    snprintf(what, sizeof what, "tree build (%zu tris, depth %d)", m->ntris, t.depth);
    row(ORGANS[oi], what, samples, (size_t)reps, NAN);
    for (int r = 0; r < reps; r++) {
      uint64_t t0 = vtime_mono_ns();
      aabb_tree_refit(&t, m->pos);
      samples[r] = (double)(vtime_mono_ns() - t0) * 1e-3;
    }
    row(ORGANS[oi], "tree refit, at rest", samples, (size_t)reps, NAN);
    /* Every vertex moved beyond the margin: alternate with a shifted copy. */
    double *xs = malloc(3 * m->nverts * sizeof *xs);
    if (xs) {
      for (size_t c = 0; c < 3 * m->nverts; c++) xs[c] = m->pos[c] + 1e-3;
      for (int r = 0; r < reps; r++) {
        uint64_t t0 = vtime_mono_ns();
        aabb_tree_refit(&t, (r & 1) ? m->pos : xs);
        samples[r] = (double)(vtime_mono_ns() - t0) * 1e-3;
      }
      row(ORGANS[oi], "tree refit, every vertex moved", samples, (size_t)reps, NAN);
      aabb_tree_refit(&t, m->pos);
      free(xs);
    }
    aabb_tree_destroy(&t);
    node_grid_t g;
    for (int r = 0; r < reps; r++) {
      uint64_t t0 = vtime_mono_ns();
      node_grid_create(&g, m->pos, m->nverts, 0, &err);
      samples[r] = (double)(vtime_mono_ns() - t0) * 1e-3;
      if (r + 1 < reps) node_grid_destroy(&g);
    }
    row(ORGANS[oi], "grid create", samples, (size_t)reps, NAN);
    for (int r = 0; r < reps; r++) {
      uint64_t t0 = vtime_mono_ns();
      node_grid_rebuild(&g, m->pos);
      samples[r] = (double)(vtime_mono_ns() - t0) * 1e-3;
    }
    row(ORGANS[oi], "grid rebuild", samples, (size_t)reps, NAN);
    node_grid_destroy(&g);
  }

  /* Queries on the liver (the 23,522-vertex target mesh). */
  mesh_t *liver = &meshes[norgans - 1];
  const char *lname = ORGANS[norgans - 1];
  size_t nq = quick ? 20000 : 200000;
  double *us = malloc(nq * sizeof *us);
  aabb_tree_t lt;
  verr_t err;
  aabb_tree_build(&lt, liver->pos, liver->nverts, liver->tris, liver->ntris, &err);
  header("nearest surface point (random points: on the surface, within 2 mm, within 5 mm; and a sliding path)");
  double *q = malloc(3 * nq * sizeof *q);
  random_queries(liver, liver->pos, 0, q, nq);
  bench_nearest(lname, "tree, on the surface", &lt, q, nq, us);
  random_queries(liver, liver->pos, 0.002, q, nq);
  bench_nearest(lname, "tree, within 2 mm", &lt, q, nq, us);
  random_queries(liver, liver->pos, 0.005, q, nq);
  bench_nearest(lname, "tree, within 5 mm", &lt, q, nq, us);
  path_queries(liver, &lt, q, nq);
  bench_nearest(lname, "tree, sliding path", &lt, q, nq, us);
  double *xd = malloc(3 * liver->nverts * sizeof *xd);
  deform(liver->pos, xd, liver->nverts, 0.01);
  aabb_tree_refit(&lt, xd);
  random_queries(liver, xd, 0.005, q, nq);
  bench_nearest(lname, "tree, within 5 mm, deformed 1 cm", &lt, q, nq, us);
  aabb_tree_refit(&lt, liver->pos);
  size_t nscan = quick ? 50 : 500;
  random_queries(liver, liver->pos, 0.005, q, nscan);
  for (size_t i = 0; i < nscan; i++) {
    uint64_t t0 = vtime_mono_ns();
    scan_nearest(liver->pos, liver->tris, liver->ntris, q + 3 * i);
    us[i] = (double)(vtime_mono_ns() - t0) * 1e-3;
  }
  row(lname, "scan over all triangles", us, nscan, NAN);

  header("first entering hit, 2 cm segments crossing the surface");
  for (size_t i = 0; i < nq; i++) {
    double c[3], n[3], p0[3], p1[3];
    near_surface(liver->pos, liver->tris, liver->ntris, 0, c, n);
    for (int k = 0; k < 3; k++) {
      p0[k] = c[k] + 0.01 * n[k];
      p1[k] = c[k] - 0.01 * n[k];
    }
    aabb_hit_t h;
    uint64_t t0 = vtime_mono_ns();
    int hit = aabb_tree_segment_first(&lt, p0, p1, AABB_SEG_ENTERING, INFINITY, &h);
    us[i] = (double)(vtime_mono_ns() - t0) * 1e-3;
    sink += hit;
  }
  row(lname, "tree segment_first", us, nq, NAN);

  header("nearest node, random points within 5 mm of the surface");
  node_grid_t g;
  node_grid_create(&g, liver->pos, liver->nverts, 0, &err);
  random_queries(liver, liver->pos, 0.005, q, nq);
  for (size_t i = 0; i < nq; i++) {
    double d2;
    uint64_t t0 = vtime_mono_ns();
    uint32_t id = node_grid_nearest(&g, q + 3 * i, &d2);
    us[i] = (double)(vtime_mono_ns() - t0) * 1e-3;
    sink += id;
  }
  uint64_t b0 = vtime_mono_ns();
  for (size_t i = 0; i < nq; i++) {
    double d2;
    sink += node_grid_nearest(&g, q + 3 * i, &d2);
  }
  double batch = (double)(vtime_mono_ns() - b0) * 1e-3 / (double)nq;
  char what[64];
  snprintf(what, sizeof what, "grid (cell %.1f mm)", 1e3 * g.cell);
  row(lname, what, us, nq, batch);
  for (size_t i = 0; i < nscan * 10; i++) {
    const double *qi = q + 3 * i;
    uint64_t t0 = vtime_mono_ns();
    double best = INFINITY;
    for (size_t v = 0; v < liver->nverts; v++) {
      double d[3];
      v3_sub(d, liver->pos + 3 * v, qi);
      best = fmin(best, v3_dot(d, d));
    }
    us[i] = (double)(vtime_mono_ns() - t0) * 1e-3;
    sink += best;
  }
  row(lname, "linear scan over nodes", us, nscan * 10, NAN);
  node_grid_destroy(&g);

  header("proxy_update per haptic step (press 1 cm, slide 2 cm, leave)");
  int presses = quick ? 10 : 100;
  double *ut = malloc(100 * (size_t)presses * sizeof *ut), *uscan = malloc(100 * (size_t)presses * sizeof *uscan);
  for (size_t oi = 0; oi < norgans; oi++) {
    mesh_t *m = &meshes[oi];
    aabb_tree_t t;
    aabb_tree_build(&t, m->pos, m->nverts, m->tris, m->ntris, &err);
    size_t ns;
    bench_proxy(ORGANS[oi], m, &t, presses, ut, uscan, &ns);
    aabb_tree_destroy(&t);
  }
  free(ut);
  free(uscan);
  free(q);
  free(xd);
  free(us);
  aabb_tree_destroy(&lt);
  for (size_t oi = 0; oi < norgans; oi++) mesh_free(&meshes[oi]);
  if (csv) fclose(csv);
  return 0;
}
