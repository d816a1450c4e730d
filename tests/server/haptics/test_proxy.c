/* SPDX-License-Identifier: Apache-2.0 */
/* God-object proxy on a flat square patch (z = 0, normal +z) and on a closed
 * octahedron: force f = K (proxy - device) (docs/methods.md A eq. 12), proxy stays on
 * the surface however deep the device goes, clamped force, release above the
 * surface, frictionless sliding, no contact from behind.
 * Then the same proxy with AABB trees against the scan over triangles, on two
 * generated organs side by side that deform every step (a travelling wave
 * and a dent under the tool) with the trees refit each step: a scripted path
 * of touches, deep presses, slides and releases must give identical proxy
 * state and force at every step; a tree refit from another array must be
 * ignored (the scan runs). The organ part skips (77) without
 * VISCERA_SOURCE_DIR. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_rng.h"
#include "test_assets.h"
#include "collision/aabb_tree.h"
#include "haptics/proxy.h"
#include "mesh.h"
#include "mesh_import.h"
#include "vmath.h"

static uint64_t rng_state = 0x853c49e6748fea9bull;
static double urand(void) { return test_rng_uniform(&rng_state); }

typedef struct organ {
  mesh_t m;
  double *x;      /* current positions */
  double *normal; /* rest vertex normals (area weighted) */
  double max_edge;
  aabb_tree_t tree;
} organ_t;

static int organ_load(organ_t *o, const char *dir, const char *name, const double offset[3]) {
  (void)dir; /* the support library finds the assets */
  if (test_organ_load(name, &o->m)) return -1;
  size_t n = o->m.nverts;
  for (size_t i = 0; i < n; i++)
    for (int k = 0; k < 3; k++) o->m.pos[3 * i + (size_t)k] += offset[k];
  o->x = malloc(3 * n * sizeof *o->x);
  o->normal = calloc(3 * n, sizeof *o->normal);
  memcpy(o->x, o->m.pos, 3 * n * sizeof *o->x);
  o->max_edge = 0;
  for (size_t t = 0; t < o->m.ntris; t++) {
    const uint32_t *v = o->m.tris + 3 * t;
    double e1[3], e2[3], nt[3];
    v3_sub(e1, o->m.pos + 3 * v[1], o->m.pos + 3 * v[0]);
    v3_sub(e2, o->m.pos + 3 * v[2], o->m.pos + 3 * v[0]);
    v3_cross(nt, e1, e2);
    for (int j = 0; j < 3; j++) {
      v3_axpy(o->normal + 3 * v[j], nt, 1.0);
      o->max_edge = fmax(o->max_edge, v3_dist(o->m.pos + 3 * v[j], o->m.pos + 3 * v[(j + 1) % 3]));
    }
  }
  for (size_t i = 0; i < n; i++) v3_normalize(o->normal + 3 * i);
  verr_t err;
  return aabb_tree_build(&o->tree, o->x, n, o->m.tris, o->m.ntris, &err);
}

static void organ_free(organ_t *o) {
  aabb_tree_destroy(&o->tree);
  free(o->x);
  free(o->normal);
  mesh_free(&o->m);
}

/* The tissue's motion for step s: a travelling wave of 2 mm everywhere and
 * a 4 mm dent under the device when it is close (what a pressed organ does). */
static void organ_move(organ_t *o, int s, const double device[3]) {
  for (size_t i = 0; i < o->m.nverts; i++) {
    const double *r = o->m.pos + 3 * i;
    double *p = o->x + 3 * i;
    double w = 0.002 * sin(0.05 * s + 40 * r[0] + 25 * r[1]);
    double d = v3_dist(r, device), dent = 0.004 * exp(-d * d / (2 * 0.008 * 0.008));
    for (int k = 0; k < 3; k++) p[k] = r[k] + (w - dent) * o->normal[3 * i + (size_t)k];
  }
}

static int same_proxy(const proxy_t *a, const proxy_t *b) {
  if (a->in_contact != b->in_contact || a->surface != b->surface) return 0;
  if (memcmp(a->pos, b->pos, sizeof a->pos) || memcmp(a->device_prev, b->device_prev, sizeof a->pos)) return 0;
  if (!a->in_contact) return 1;
  return a->tri == b->tri && !memcmp(a->bary, b->bary, sizeof a->bary) &&
         !memcmp(a->normal, b->normal, sizeof a->normal);
}

static void tree_vs_scan(const char *dir) {
  organ_t org[2];
  memset(org, 0, sizeof org);
  /* Kidney (11 cm) and spleen (12 cm) 5 mm apart along x, so paths near the
   * gap see both surfaces. */
  if (organ_load(&org[0], dir, "kidney", (double[]){0, 0, 0}) ||
      organ_load(&org[1], dir, "spleen", (double[]){0.12, 0, 0})) {
    CHECK(0);
    return;
  }
  proxy_surface_t scan[2], tree[2], stale[2];
  for (int i = 0; i < 2; i++) {
    scan[i] = (proxy_surface_t){.x = org[i].x,
                                .tris = org[i].m.tris,
                                .ntris = org[i].m.ntris,
                                .max_edge = 3 * org[i].max_edge,
                                .x_rest = org[i].m.pos};
    tree[i] = scan[i];
    tree[i].tree = &org[i].tree;
  }
  /* A tree refit from a copy of the positions describes a different array:
   * the proxy must not use it. */
  organ_t *k = &org[0];
  double *copy = malloc(3 * k->m.nverts * sizeof *copy);
  aabb_tree_t other;
  verr_t err;
  CHECK(aabb_tree_build(&other, k->x, k->m.nverts, k->m.tris, k->m.ntris, &err) == 0);
  stale[0] = tree[0];
  stale[0].tree = &other;
  stale[1] = tree[1];
  proxy_t ps, pt, pz;
  proxy_reset(&ps);
  proxy_reset(&pt);
  proxy_reset(&pz);
  int steps = 0, contact = 0, mismatch = 0, hit_surface[2] = {0, 0};
  double device[3] = {0, 0, 0.2}, peak = 0;
  for (int target = 0; target < 24; target++) {
    /* A vertex of either organ; the device comes down its normal from 2 cm
     * out to 1 cm (later ones 3 cm) in, slides 2 cm sideways, leaves. */
    organ_t *o = &org[target % 2];
    size_t v = (size_t)(urand() * (double)o->m.nverts);
    const double *p = o->m.pos + 3 * v, *n = o->normal + 3 * v;
    double side[3], t1[3] = {urand() - 0.5, urand() - 0.5, urand() - 0.5};
    v3_cross(side, n, t1);
    v3_normalize(side);
    double depth = target < 12 ? 0.01 : 0.03;
    for (int s = 0; s < 60; s++, steps++) {
      double out = s < 20   ? 0.02 - (0.02 + depth) * s / 19.0
                   : s < 45 ? -depth
                            : -depth + (0.02 + depth) * (s - 44) / 15.0;
      double slide = s < 20 ? 0 : s < 45 ? 0.02 * (s - 20) / 24.0 : 0.02;
      for (int c = 0; c < 3; c++) device[c] = p[c] + out * n[c] + slide * side[c];
      for (int i = 0; i < 2; i++) {
        organ_move(&org[i], steps, device);
        aabb_tree_refit(&org[i].tree, org[i].x);
      }
      memcpy(copy, k->m.pos, 3 * k->m.nverts * sizeof *copy); /* the stale tree keeps rest positions */
      aabb_tree_refit(&other, copy);
      /* The runtime's order: follow the moved surface, then the haptic update. */
      proxy_follow_surface(&ps, scan, 2);
      proxy_follow_surface(&pt, tree, 2);
      proxy_follow_surface(&pz, stale, 2);
      double fs[3], ft[3], fz[3];
      int rs = proxy_update(&ps, device, scan, 2, 300, 4, fs);
      int rt = proxy_update(&pt, device, tree, 2, 300, 4, ft);
      int rz = proxy_update(&pz, device, stale, 2, 300, 4, fz);
      int ok = rs == rt && rs == rz && same_proxy(&ps, &pt) && same_proxy(&ps, &pz) && !memcmp(fs, ft, sizeof fs) &&
               !memcmp(fs, fz, sizeof fs);
      if (!ok && mismatch++ < 3)
        fprintf(stderr, "tree_vs_scan step %d: scan %d surface %d tri %u, tree %d surface %d tri %u, stale %d tri %u\n",
                steps, rs, ps.surface, ps.tri, rt, pt.surface, pt.tri, rz, pz.tri);
      contact += rs;
      if (rs) hit_surface[ps.surface]++;
      peak = fmax(peak, v3_norm(fs));
    }
  }
  printf("tree_vs_scan: %d steps, %d in contact (kidney %d, spleen %d), peak force %.2f N, %d mismatches\n", steps,
         contact, hit_surface[0], hit_surface[1], peak, mismatch);
  CHECK(mismatch == 0);
  /* Not vacuous: most of each press is in contact, on both organs, some clamped. */
  CHECK(contact > steps / 3);
  CHECK(hit_surface[0] > 100 && hit_surface[1] > 100);
  CHECK_NEAR(peak, 4, 1e-9);
  aabb_tree_destroy(&other);
  free(copy);
  organ_free(&org[0]);
  organ_free(&org[1]);
}

int main(void) {
  double x[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  uint32_t tris[] = {0, 1, 2, 0, 2, 3};
  proxy_surface_t s = {x, tris, 2, 0, NULL, NULL, NULL, 0};
  proxy_t p;
  proxy_reset(&p);
  double f[3];
  /* Free above the surface. */
  CHECK(proxy_update(&p, (double[]){0.2, 0.1, 0.5}, &s, 1, 100, 1e9, f) == 0);
  CHECK(v3_norm(f) == 0);
  /* Moving 1 cm below: contact, proxy on the surface above the device. */
  CHECK(proxy_update(&p, (double[]){0.2, 0.1, -0.01}, &s, 1, 100, 1e9, f) == 1);
  CHECK_NEAR(p.pos[2], 0, 1e-12);
  CHECK_NEAR(p.pos[0], 0.2, 1e-12);
  CHECK_NEAR(f[2], 1.0, 1e-9); /* 100 N/m * 1 cm */
  CHECK_NEAR(f[0], 0, 1e-12);
  /* Deep push (10 cm below) with a 4 N device: proxy stays on the surface, force clamped. */
  CHECK(proxy_update(&p, (double[]){0.2, 0.1, -0.1}, &s, 1, 100, 4, f) == 1);
  CHECK_NEAR(p.pos[2], 0, 1e-12);
  CHECK_NEAR(v3_norm(f), 4, 1e-9);
  /* Sliding sideways while inside: proxy follows in the tangent plane. */
  CHECK(proxy_update(&p, (double[]){0.5, -0.3, -0.02}, &s, 1, 100, 1e9, f) == 1);
  CHECK_NEAR(p.pos[0], 0.5, 1e-12);
  CHECK_NEAR(p.pos[1], -0.3, 1e-12);
  CHECK_NEAR(f[2], 2.0, 1e-9);
  CHECK(proxy_spring_force(&p, (double[]){0.5, -0.3, -0.02}, 100, 1e9, f) > 0);
  /* Just above the plane (within the release margin): still touching, zero force. */
  CHECK(proxy_update(&p, (double[]){0.5, -0.3, 0.5 * PROXY_RELEASE_MARGIN}, &s, 1, 100, 1e9, f) == 1);
  CHECK(v3_norm(f) == 0);
  /* Back above: released, zero force. */
  CHECK(proxy_update(&p, (double[]){0.5, -0.3, 0.01}, &s, 1, 100, 1e9, f) == 0);
  CHECK(v3_norm(f) == 0);
  CHECK(p.in_contact == 0);
  /* Approaching from behind (below, moving up through) is not a contact. */
  proxy_reset(&p);
  proxy_update(&p, (double[]){0, 0, -0.5}, &s, 1, 100, 1e9, f);
  CHECK(proxy_update(&p, (double[]){0, 0, 0.5}, &s, 1, 100, 1e9, f) == 0);
  /* The surface moving under a held device: the proxy follows it. */
  proxy_reset(&p);
  proxy_update(&p, (double[]){0.1, 0.1, 0.2}, &s, 1, 100, 1e9, f);
  proxy_update(&p, (double[]){0.1, 0.1, -0.05}, &s, 1, 100, 1e9, f);
  for (int i = 0; i < 4; i++) x[3 * i + 2] = -0.03;
  proxy_follow_surface(&p, &s, 1);
  CHECK_NEAR(p.pos[2], -0.03, 1e-12);
  CHECK_NEAR(proxy_spring_force(&p, (double[]){0.1, 0.1, -0.05}, 100, 1e9, f), 2.0, 1e-9);
  const char *dir = getenv("VISCERA_SOURCE_DIR");
  if (!dir) {
    fprintf(stderr, "test_proxy: VISCERA_SOURCE_DIR not set; skipping the tree against scan comparison\n");
    check_report("test_proxy");
    return 77;
  }
  tree_vs_scan(dir);
  return check_report("test_proxy");
}
