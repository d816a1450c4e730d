/* SPDX-License-Identifier: Apache-2.0 */
/* The vertex culls (runtime/vertex_cull.h, issue 17): the contact patch
 * and the shafts' node test gather their candidates from the organ's AABB
 * tree instead of scanning every surface vertex, and must give the scan's
 * results bit for bit. Two runtimes of the same scene take the same random
 * presses (random surface point, depth, tilt of the shaft, slide): one
 * culls, the other scans (cull.force_scan); after every step their surface
 * positions, patches (indices and weights), hand forces and shaft
 * reactions must be equal to the bit. Scenes: the shipped gallbladder and
 * kidney seats, the mass-spring block after a scalpel cut (new topology),
 * a probe as wide as the organ (candidates = most of it), each fallback
 * forced (a model that cannot say what moved, an incomplete surface, a
 * tree over other positions or another surface, a NaN query), and a
 * cull whose radius is shrunk below the proven one, which must differ from
 * the scan (so the comparison can fail). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_runtime.h"
#include "collision/aabb_tree.h"
#include "runtime/scene_runtime.h"
#include "runtime/vertex_cull.h"
#include "vmath.h"

static runtime_t ra, rb; /* large: ra culls, rb scans */
static scene_t sa, sb;

typedef struct diffs {
  long steps, state, patch, force, shaft, shaft_steps;
} diffs_t;

static uint64_t rng = 88172645463325252ull;
static double urand(void) {
  rng ^= rng << 13;
  rng ^= rng >> 7;
  rng ^= rng << 17;
  return (double)(rng >> 11) / 9007199254740992.0;
}

static void compare(diffs_t *d) {
  d->steps++;
  for (size_t i = 0; i < ra.norgans; i++) {
    const model_t *a = ra.organs[i].model, *b = rb.organs[i].model;
    if (a->nsurf != b->nsurf || memcmp(a->surf_x, b->surf_x, 3 * a->nsurf * sizeof(double))) d->state++;
  }
  for (size_t t = 0; t < ra.ntools; t++) {
    const tool_rt_t *a = &ra.tools[t], *b = &rb.tools[t];
    if (a->npatch != b->npatch || memcmp(a->patch, b->patch, a->npatch * sizeof a->patch[0]) ||
        memcmp(a->patch_w, b->patch_w, a->npatch * sizeof a->patch_w[0]))
      d->patch++;
    if (memcmp(a->force, b->force, sizeof a->force)) d->force++;
    if (a->from.shaft_hits != b->from.shaft_hits || memcmp(a->from.shaft, b->from.shaft, sizeof a->from.shaft))
      d->shaft++;
    if (b->from.shaft_hits) d->shaft_steps++;
  }
}

static void step_both(size_t t, const double pos[3], const double q[4], uint32_t buttons, diffs_t *d) {
  runtime_t *rs[2] = {&ra, &rb};
  for (int k = 0; k < 2; k++) {
    runtime_set_tool(rs[k], t, pos, 4);
    runtime_set_orientation(rs[k], t, q);
    runtime_set_buttons(rs[k], t, buttons);
    runtime_step(rs[k]);
  }
  compare(d);
}

/* The unit quaternion turning +z onto unit a (a not -z). */
static void quat_to(const double a[3], double q[4]) {
  q[0] = 1 + a[2];
  q[1] = -a[1];
  q[2] = a[0];
  q[3] = 0;
  double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
  for (int k = 0; k < 4; k++) q[k] /= n;
}

/* The mean normal of the triangles around vertex v of organ i (current
 * surface of ra). */
static void vertex_normal(size_t i, uint32_t v, double n[3]) {
  const model_t *m = ra.organs[i].model;
  v3_set(n, 0, 0, 0);
  for (size_t t = 0; t < m->nsurf_tris; t++) {
    const uint32_t *tri = m->surf_tris + 3 * t;
    if (tri[0] != v && tri[1] != v && tri[2] != v) continue;
    double e1[3], e2[3], c[3];
    v3_sub(e1, m->surf_x + 3 * tri[1], m->surf_x + 3 * tri[0]);
    v3_sub(e2, m->surf_x + 3 * tri[2], m->surf_x + 3 * tri[0]);
    v3_cross(c, e1, e2);
    v3_add(n, n, c);
  }
  if (!(v3_normalize(n) > 0)) v3_set(n, 0, 0, 1);
}

/* Tool t presses organ i at a random vertex: in along the normal to a
 * random depth with the shaft tilted at random (up to ~70 degrees, so it
 * often lies on the tissue), held, slid sideways, lifted. */
static void press(size_t t, size_t i, diffs_t *d) {
  const model_t *m = ra.organs[i].model;
  uint32_t v = (uint32_t)(urand() * (double)m->nsurf) % (uint32_t)m->nsurf;
  double n[3], u[3], a[3], q[4], p0[3], p1[3], p2[3];
  vertex_normal(i, v, n);
  for (int k = 0; k < 3; k++) u[k] = urand() - 0.5;
  v3_copy(a, n);
  v3_axpy(a, u, 6 * urand());
  if (!(v3_normalize(a) > 0) || a[2] < -0.9) v3_copy(a, n);
  if (a[2] < -0.9) v3_set(a, 0, 0, 1);
  quat_to(a, q);
  double depth = 0.0005 + 0.0035 * urand();
  v3_copy(p0, m->surf_x + 3 * (size_t)v);
  v3_axpy(p0, n, 0.008);
  v3_copy(p1, m->surf_x + 3 * (size_t)v);
  v3_axpy(p1, n, -depth);
  v3_copy(p2, p1);
  v3_axpy(p2, u, 0.006);
  double p[3];
  for (int s = 1; s <= 25; s++) {
    for (int k = 0; k < 3; k++) p[k] = p0[k] + (p1[k] - p0[k]) * s / 25;
    step_both(t, p, q, 0, d);
  }
  for (int s = 0; s < 10; s++) step_both(t, p1, q, 0, d);
  for (int s = 1; s <= 20; s++) {
    for (int k = 0; k < 3; k++) p[k] = p1[k] + (p2[k] - p1[k]) * s / 20;
    step_both(t, p, q, 0, d);
  }
  for (int s = 1; s <= 8; s++) {
    for (int k = 0; k < 3; k++) p[k] = p2[k] + (p0[k] - p2[k]) * s / 8;
    step_both(t, p, q, 0, d);
  }
}

static void report(const char *what, const diffs_t *d) {
  printf("  %-34s %5ld steps (shaft touching in %4ld): differ state %ld, patch %ld, force %ld, shaft %ld; "
         "culled patch %llu / scanned %llu, culled shaft %llu / scanned %llu\n",
         what, d->steps, d->shaft_steps, d->state, d->patch, d->force, d->shaft,
         (unsigned long long)ra.cull.patch_culls, (unsigned long long)ra.cull.patch_scans,
         (unsigned long long)ra.cull.shaft_culls, (unsigned long long)ra.cull.shaft_scans);
}

static int equal(const diffs_t *d) { return d->state == 0 && d->patch == 0 && d->force == 0 && d->shaft == 0; }

static int load_both(const char *scene_file, const char *yaml) {
  int ok = scene_file ? test_runtime_load_scene(&ra, &sa, scene_file, NULL) &&
                            test_runtime_load_scene(&rb, &sb, scene_file, NULL)
                      : test_runtime_load(&ra, &sa, yaml, NULL) && test_runtime_load(&rb, &sb, yaml, NULL);
  rb.cull.force_scan = 1;
  return ok;
}

static void destroy_both(void) {
  runtime_destroy(&ra);
  runtime_destroy(&rb);
}

/* The shipped seats: every press equal to the bit, culls used. */
static void test_seat(const char *scene_file, int presses) {
  CHECK(load_both(scene_file, NULL));
  diffs_t d = {0};
  for (int k = 0; k < presses; k++) press(0, 0, &d);
  report(scene_file, &d);
  CHECK(equal(&d));
  CHECK(d.shaft_steps > 0); /* the shaft did touch tissue */
  CHECK(ra.cull.patch_culls > 0 && ra.cull.patch_scans == 0);
  CHECK(ra.cull.shaft_culls > 0);
  CHECK(rb.cull.patch_culls == 0 && rb.cull.shaft_culls == 0);
  destroy_both();
}

/* The mass-spring block cut by a scalpel (new vertices, new triangles),
 * then probed around the wound. */
static void test_after_cut(void) {
  const char *yaml = "scene: t\n"
                     "organs:\n"
                     "  - name: block\n"
                     "    mesh: ../meshes/tissue_block.obj\n"
                     "    model: mass_spring_surface\n"
                     "    position: [0, 0, -0.1]\n"
                     "tools:\n"
                     "  - {name: knife, kind: scalpel, radius: 0.001}\n"
                     "  - {name: probe, kind: probe, radius: 0.003, length: 0.1, stiffness: 400, max_force: 4}\n";
  CHECK(load_both(NULL, yaml));
  diffs_t d = {0};
  double up[4] = {1, 0, 0, 0}, park[3] = {0.5, 0.5, 0.5};
  /* The probe waits far away; the knife goes in, across and out. */
  step_both(1, park, up, 0, &d);
  double top = -0.1, y = 0.005,
         pts[4][3] = {{-0.03, y, top + 0.02}, {-0.03, y, top - 0.005}, {0.03, y, top - 0.005}, {0.03, y, top + 0.02}};
  int counts[3] = {200, 400, 200};
  for (int seg = 0; seg < 3; seg++)
    for (int s = 1; s <= counts[seg]; s++) {
      double p[3];
      for (int k = 0; k < 3; k++) p[k] = pts[seg][k] + (pts[seg + 1][k] - pts[seg][k]) * s / counts[seg];
      step_both(0, p, up, 1, &d);
    }
  for (int s = 0; s < 20; s++) step_both(0, pts[3], up, 0, &d);
  CHECK(ra.organs[0].model->topology_version > 0);
  for (int k = 0; k < 25; k++) press(1, 0, &d);
  report("block after a cut", &d);
  CHECK(equal(&d));
  CHECK(ra.cull.patch_culls > 0 && ra.cull.shaft_culls > 0);
  destroy_both();
}

/* A model that cannot tell what moved (regional sleeping off: the
 * sub-steps' shaft test scans, the after-step one culls), and a probe as
 * wide as the organ (most of it candidates): equal still. */
static void test_fallbacks_runtime(void) {
  verr_t e;
  CHECK(test_runtime_one_organ(&ra, &sa, "t", "kidney.obj",
                               "    model: mass_spring_surface\n    solver: {region_force: 0}\n",
                               "radius: 0.003, length: 0.1, stiffness: 400, max_force: 4", &e));
  CHECK(test_runtime_one_organ(&rb, &sb, "t", "kidney.obj",
                               "    model: mass_spring_surface\n    solver: {region_force: 0}\n",
                               "radius: 0.003, length: 0.1, stiffness: 400, max_force: 4", &e));
  rb.cull.force_scan = 1;
  diffs_t d = {0};
  for (int k = 0; k < 6; k++) press(0, 0, &d);
  report("kidney, no regional sleeping", &d);
  CHECK(equal(&d));
  CHECK(ra.cull.patch_culls > 0 && ra.cull.shaft_culls > 0 && ra.cull.shaft_scans > 0);
  destroy_both();
  CHECK(test_runtime_one_organ(&ra, &sa, "t", "kidney.obj", "",
                               "radius: 0.05, length: 0.3, stiffness: 400, max_force: 4", &e));
  CHECK(test_runtime_one_organ(&rb, &sb, "t", "kidney.obj", "",
                               "radius: 0.05, length: 0.3, stiffness: 400, max_force: 4", &e));
  rb.cull.force_scan = 1;
  memset(&d, 0, sizeof d);
  for (int k = 0; k < 4; k++) press(0, 0, &d);
  report("kidney, probe wider than the organ", &d);
  CHECK(equal(&d));
  CHECK(ra.cull.patch_culls > 0);
  destroy_both();
}

/* vertex_cull itself: a vertex no triangle uses, a tree over another
 * position array or surface (no cull), a vertex moved since the refit (found
 * only when added), ascending order, a NaN query (no cull). */
static void test_fallbacks_unit(void) {
  double x[3 * 5] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 5, 5, 5};
  uint32_t tris[6] = {0, 1, 2, 1, 3, 2};
  aabb_tree_t tree;
  vertex_cull_t c = {0};
  verr_t e;
  CHECK(aabb_tree_build(&tree, x, 5, tris, 2, &e) == 0);
  CHECK(vertex_cull_setup(&c, 5, tris, 2, &e) == 0);
  CHECK(!c.complete && !vertex_cull_usable(&c, &tree, x, 5, 2)); /* vertex 4 is no corner */
  aabb_tree_destroy(&tree);
  CHECK(aabb_tree_build(&tree, x, 4, tris, 2, &e) == 0);
  CHECK(vertex_cull_setup(&c, 4, tris, 2, &e) == 0);
  CHECK(c.complete && vertex_cull_usable(&c, &tree, x, 4, 2));
  double other[12];
  memcpy(other, x, sizeof other);
  CHECK(!vertex_cull_usable(&c, &tree, other, 4, 2)); /* the tree reads other positions */
  CHECK(!vertex_cull_usable(&c, &tree, x, 4, 1) && !vertex_cull_usable(&c, NULL, x, 4, 2));
  /* A box around vertex 3 gives vertex 3; single vertices come ascending,
   * each once. */
  const uint32_t *out;
  double lo[3] = {0.9, 0.9, -0.1}, hi[3] = {1.1, 1.1, 0.1};
  vertex_cull_begin(&c);
  vertex_cull_box(&c, &tree, lo, hi);
  size_t n = vertex_cull_take(&c, &out);
  CHECK(n == 1 && out[0] == 3);
  vertex_cull_begin(&c);
  vertex_cull_add(&c, 3);
  vertex_cull_add(&c, 0);
  vertex_cull_add(&c, 3);
  vertex_cull_add(&c, 99); /* out of range: ignored */
  n = vertex_cull_take(&c, &out);
  CHECK(n == 2 && out[0] == 0 && out[1] == 3);
  /* A vertex moved since the refit, far beyond its leaf's box, is found
   * only when the caller adds it (the model's moved list). */
  x[9] = 3;
  double lo2[3] = {2.9, 0.9, -0.1}, hi2[3] = {3.1, 1.1, 0.1};
  vertex_cull_begin(&c);
  vertex_cull_box(&c, &tree, lo2, hi2);
  CHECK(vertex_cull_take(&c, &out) == 0);
  vertex_cull_begin(&c);
  vertex_cull_box(&c, &tree, lo2, hi2);
  vertex_cull_add(&c, 3);
  CHECK(vertex_cull_take(&c, &out) == 1 && out[0] == 3);
  aabb_tree_refit(&tree, x);
  vertex_cull_begin(&c);
  vertex_cull_box(&c, &tree, lo2, hi2);
  CHECK(vertex_cull_take(&c, &out) == 1 && out[0] == 3); /* after the refit the tree finds it */
  aabb_tree_destroy(&tree);
  vertex_cull_free(&c);
  /* A grid: a segment over all of it gives every vertex, ascending; one
   * down through a cell its four corners; a NaN segment SIZE_MAX. */
  size_t g = 40, nv = (g + 1) * (g + 1), nt = 2 * g * g;
  double *gx = malloc(3 * nv * sizeof *gx);
  uint32_t *gt = malloc(3 * nt * sizeof *gt);
  CHECK(gx && gt);
  for (size_t j = 0; j <= g; j++)
    for (size_t i = 0; i <= g; i++) v3_set(gx + 3 * (j * (g + 1) + i), (double)i, (double)j, 0);
  for (size_t j = 0, k = 0; j < g; j++)
    for (size_t i = 0; i < g; i++, k += 6) {
      uint32_t a = (uint32_t)(j * (g + 1) + i), b = a + 1, cc = a + (uint32_t)g + 1, dd = cc + 1;
      uint32_t q[6] = {a, b, cc, b, dd, cc};
      memcpy(gt + k, q, sizeof q);
    }
  CHECK(aabb_tree_build(&tree, gx, nv, gt, nt, &e) == 0);
  CHECK(vertex_cull_setup(&c, nv, gt, nt, &e) == 0 && vertex_cull_usable(&c, &tree, gx, nv, nt));
  double p0[3] = {-1, -1, 0}, p1[3] = {g + 1.0, g + 1.0, 0};
  n = vertex_cull_segment(&c, &tree, p0, p1, 100, NULL, 0, &out);
  CHECK(n == nv);
  int asc = 1;
  for (size_t k = 0; k < n && n == nv; k++) asc &= out[k] == k;
  CHECK(asc);
  double s0[3] = {2.5, 2.5, 1}, s1[3] = {2.5, 2.5, -1};
  n = vertex_cull_segment(&c, &tree, s0, s1, 0.75, NULL, 0, &out);
  CHECK(n == 4 && out[0] == 2 * (g + 1) + 2 && out[3] == 3 * (g + 1) + 3);
  s1[0] = NAN;
  CHECK(vertex_cull_segment(&c, &tree, s0, s1, 0.75, NULL, 0, &out) == SIZE_MAX);
  s1[0] = 2.5;
  CHECK(vertex_cull_segment(&c, &tree, s0, s1, 0.75, NULL, 0, &out) == 4); /* clear again afterwards */
  aabb_tree_destroy(&tree);
  vertex_cull_free(&c);
  free(gx);
  free(gt);
}

/* A cull short of its proven radius misses vertices: the patch (or, with
 * the shaft's radius shrunk, the shaft's pushes) then differ from the scan. */
static void test_shrunk_margin(void) {
  CHECK(load_both("classroom_gallbladder.yaml", NULL));
  ra.cull.patch_scale = 0.5;
  diffs_t d = {0};
  for (int k = 0; k < 3; k++) press(0, 0, &d);
  report("patch radius x 0.5 (must differ)", &d);
  CHECK(d.patch > 0);
  destroy_both();
  CHECK(load_both("classroom_gallbladder.yaml", NULL));
  ra.cull.shaft_scale = 0.5;
  memset(&d, 0, sizeof d);
  for (int k = 0; k < 12 && d.shaft == 0; k++) press(0, 0, &d);
  report("shaft radius x 0.5 (must differ)", &d);
  CHECK(d.shaft > 0 || d.state > 0);
  destroy_both();
}

int main(void) {
  test_fallbacks_unit();
  test_seat("classroom_gallbladder.yaml", 14);
  test_seat("classroom_kidney.yaml", 14);
  test_after_cut();
  test_fallbacks_runtime();
  test_shrunk_margin();
  return check_report("test_vertex_cull");
}
