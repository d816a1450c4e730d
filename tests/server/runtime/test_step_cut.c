/* SPDX-License-Identifier: Apache-2.0 */
/* test_scalpel: the scalpel wired into the real runtime (scene files, organ
 * meshes, models; no networking):
 * - a scene without a scalpel allocates no cutting structures (no pbd
 *   cutter, no ms cutter, rt.scalpel NULL); one with a scalpel has them for
 *   the organs it can cut (xpbd, mass_spring_surface) and none for others;
 * - blade_length: default, only on a scalpel (line-numbered refusal), range;
 * - pressing the button and drawing the blade through the xpbd spleen and
 *   the mass-spring tissue block changes the topology (more surface
 *   vertices), reports IEV_CUT_BEGIN / IEV_CUT_END, and keeps every
 *   coordinate finite; the scalpel leaves the god-object while cutting;
 * - the same path with the button released cuts nothing (it touches);
 * - releasing the tool (client lost) in the middle of a cut ends it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_runtime.h"
#include "physics/pbd.h"
#include "runtime/scene_runtime.h"
#include "runtime/step_cut.h"
#include "vmath.h"

static runtime_t rt; /* large */
static scene_t sc;

static const char *SPLEEN_XPBD = "scene: t\n"
                                 "organs:\n"
                                 "  - name: spleen\n"
                                 "    mesh: ../meshes/spleen.obj\n"
                                 "    model: xpbd\n"
                                 "    material: {mass: 0.15, distance_compliance: 2.0e-3, volume_compliance: 1.0e-4}\n"
                                 "    solver: {substeps: 1, iterations: 8, tet_size: 0.005}\n";
static const char *BLOCK_MS = "  - name: block\n"
                              "    mesh: ../meshes/tissue_block.obj\n"
                              "    model: mass_spring_surface\n"
                              "    position: [0, 0, -0.1]\n";
static const char *KIDNEY_VB = "  - name: kidney\n"
                               "    mesh: ../meshes/kidney.obj\n"
                               "    model: vertex_based\n"
                               "    position: [0, 0.2, 0]\n";

static int load(const char *yaml) { return test_runtime_load(&rt, &sc, yaml, NULL); }

static int count_events(iev_kind_t kind) {
  int n = 0;
  for (size_t i = 0; i < rt.events.n; i++) n += rt.events.ev[i].kind == kind;
  return n;
}

/* Steps n times with tool t moving linearly from a to b, buttons held. */
static void drive(size_t t, const double a[3], const double b[3], int n, uint32_t buttons) {
  for (int i = 1; i <= n; i++) {
    double p[3];
    for (int k = 0; k < 3; k++) p[k] = a[k] + (b[k] - a[k]) * i / n;
    runtime_set_tool(&rt, t, p, 4);
    runtime_set_buttons(&rt, t, buttons);
    runtime_step(&rt);
  }
}

static int all_finite(const model_t *m) {
  for (size_t i = 0; i < 3 * m->nsurf; i++)
    if (!isfinite(m->surf_x[i])) return 0;
  return 1;
}

static void test_allocation(void) {
  char yaml[2048];
  /* No scalpel: nothing for cutting, whatever the models. */
  snprintf(yaml, sizeof yaml, "%s%s%stools:\n  - {name: probe, kind: probe}\n  - {name: g, kind: grasper}\n",
           SPLEEN_XPBD, BLOCK_MS, KIDNEY_VB);
  CHECK(load(yaml));
  CHECK(rt.scalpel == NULL);
  for (size_t i = 0; i < rt.norgans; i++) CHECK(!scalpel_has_cutter(&rt, i));
  CHECK(!scalpel_has_cutter(&rt, 0)); /* the models hold no cutter of their own */
  CHECK(scalpel_stats(&rt, 0) == NULL);
  runtime_destroy(&rt);
  /* A scalpel: cutters for the xpbd and mass-spring organs, none for the
   * vertex-based one (it only touches). */
  snprintf(yaml, sizeof yaml, "%s%s%stools:\n  - {name: probe, kind: probe}\n  - {name: knife, kind: scalpel}\n",
           SPLEEN_XPBD, BLOCK_MS, KIDNEY_VB);
  CHECK(load(yaml));
  CHECK(rt.scalpel != NULL);
  CHECK(scalpel_has_cutter(&rt, 0)); /* the xpbd organ's mesh copied at load */
  CHECK(scalpel_has_cutter(&rt, 0) && scalpel_has_cutter(&rt, 1) && !scalpel_has_cutter(&rt, 2));
  CHECK(scalpel_stats(&rt, 1)->can_cut && !scalpel_stats(&rt, 2)->can_cut);
  CHECK_NEAR(rt.tools[1].cfg->blade_length, 0.02, 0);
  CHECK(rt.tools[0].cfg->blade_length == 0);
  runtime_destroy(&rt);
}

static void test_scene_field(void) {
  scene_t s;
  verr_t e;
  const char *bad = "scene: t\norgans:\n  - {name: a, mesh: x.obj}\ntools:\n  - name: p\n    kind: probe\n"
                    "    blade_length: 0.01\n";
  CHECK(scene_load_string(bad, "t.yaml", NULL, &s, &e) == -1);
  CHECK(strstr(e.msg, "t.yaml:7:") && strstr(e.msg, "blade_length") && strstr(e.msg, "only a scalpel"));
  const char *range = "scene: t\norgans:\n  - {name: a, mesh: x.obj}\ntools:\n  - name: k\n    kind: scalpel\n"
                      "    blade_length: 0\n";
  CHECK(scene_load_string(range, "t.yaml", NULL, &s, &e) == -1);
  CHECK(strstr(e.msg, "t.yaml:7:") && strstr(e.msg, "blade_length"));
  const char *ok = "scene: t\norgans:\n  - {name: a, mesh: x.obj}\ntools:\n  - {name: k, kind: scalpel, "
                   "blade_length: 0.03}\n";
  CHECK(scene_load_string(ok, "t.yaml", NULL, &s, &e) == 0);
  CHECK_NEAR(s.tools[0].blade_length, 0.03, 0);
}

/* Down into the organ at `from` (depth below `top`), across to `to`, up,
 * with the button pressed (or not) the whole time. */
static void incision(size_t t, double x0, double x1, double y, double top, double depth, uint32_t button) {
  double above[3] = {x0, y, top + 0.02}, in0[3] = {x0, y, top - depth}, in1[3] = {x1, y, top - depth},
         out[3] = {x1, y, top + 0.02};
  drive(t, above, above, 20, 0);
  drive(t, above, in0, 200, button);
  drive(t, in0, in1, 400, button);
  drive(t, in1, out, 200, button);
  drive(t, out, out, 50, 0);
}

static void test_cut_xpbd(void) {
  char yaml[2048];
  snprintf(yaml, sizeof yaml, "%stools:\n  - {name: knife, kind: scalpel, radius: 0.001}\n", SPLEEN_XPBD);
  CHECK(load(yaml));
  model_t *m = rt.organs[0].model;
  size_t nv0 = m->nsurf;
  /* Button released: the scalpel touches like a probe and cuts nothing. */
  incision(0, -0.02, 0.02, 0, 0.038, 0.008, 0);
  CHECK(m->topology_version == 0 && m->nsurf == nv0);
  CHECK(count_events(IEV_CUT_BEGIN) == 0);
  CHECK(rt.tools[0].peak_force > 0.1); /* it did press on the tissue */
  rt.events.n = 0;
  /* Pressed: a straight 40 mm incision 8 mm deep. */
  double above[3] = {-0.02, 0, 0.058}, in0[3] = {-0.02, 0, 0.030}, in1[3] = {0.02, 0, 0.030};
  drive(0, above, above, 20, 0);
  drive(0, above, in0, 200, 1);
  CHECK(!rt.tools[0].proxy.in_contact); /* the blade is in the tissue, no god-object */
  drive(0, in0, in1, 400, 1);
  CHECK(m->topology_version > 0);
  CHECK(count_events(IEV_CUT_BEGIN) == 1 && count_events(IEV_CUT_END) == 0);
  double out[3] = {0.02, 0, 0.058};
  drive(0, in1, out, 200, 1);
  drive(0, out, out, 50, 0);
  CHECK(count_events(IEV_CUT_END) == 1);
  const scalpel_organ_stats_t *st = scalpel_stats(&rt, 0);
  printf("  xpbd spleen: %zu -> %zu surface vertices, topology %u, %llu changes, cut call %.0f us mean, %.0f us max\n",
         nv0, m->nsurf, m->topology_version, (unsigned long long)st->topology_changes,
         st->call_us_sum / (double)(st->calls ? st->calls : 1), st->call_us_max);
  CHECK(m->nsurf > nv0);
  CHECK(st->refused == 0 && st->cuts == 1);
  CHECK(rt.organs[0].topology_version == m->topology_version); /* the runtime followed */
  CHECK(all_finite(m));
  /* A few more steps after the cut: stable. */
  drive(0, out, out, 300, 0);
  CHECK(all_finite(m) && rt.organs[0].rollbacks == 0);
  runtime_destroy(&rt);
}

static void test_cut_ms_and_release(void) {
  char yaml[2048];
  snprintf(yaml, sizeof yaml, "scene: t\norgans:\n%stools:\n  - {name: knife, kind: scalpel, radius: 0.001}\n",
           BLOCK_MS);
  CHECK(load(yaml));
  model_t *m = rt.organs[0].model;
  size_t nv0 = m->nsurf;
  incision(0, -0.03, 0.03, 0.005, -0.1, 0.005, 1);
  const scalpel_organ_stats_t *st = scalpel_stats(&rt, 0);
  double wmean = 0, wmax = 0;
  size_t nw = scalpel_incision_width(&rt, 0, &wmean, &wmax);
  printf("  mass-spring block: %zu -> %zu surface vertices, topology %u, width %.2f / %.2f mm over %zu nodes\n", nv0,
         m->nsurf, m->topology_version, wmean * 1e3, wmax * 1e3, nw);
  CHECK(m->topology_version > 0 && m->nsurf > nv0);
  CHECK(count_events(IEV_CUT_BEGIN) >= 1 && count_events(IEV_CUT_END) == count_events(IEV_CUT_BEGIN));
  CHECK(st->refused == 0);
  CHECK(all_finite(m));
  runtime_destroy(&rt);
  /* The client is lost mid-cut: the runtime releases the tool and the next
   * step ends the cut (xpbd spleen). */
  snprintf(yaml, sizeof yaml, "%stools:\n  - {name: knife, kind: scalpel, radius: 0.001}\n", SPLEEN_XPBD);
  CHECK(load(yaml));
  m = rt.organs[0].model;
  double above[3] = {-0.02, 0, 0.058}, in0[3] = {-0.02, 0, 0.030}, mid[3] = {0.0, 0, 0.030};
  drive(0, above, in0, 200, 1);
  drive(0, in0, mid, 200, 1);
  CHECK(count_events(IEV_CUT_BEGIN) == 1);
  runtime_release_tool(&rt, 0);
  runtime_step(&rt);
  CHECK(count_events(IEV_CUT_END) == 1);
  CHECK(m->topology_version > 0 && all_finite(m));
  runtime_destroy(&rt);
}

int main(void) {
  test_scene_field();
  test_allocation();
  test_cut_xpbd();
  test_cut_ms_and_release();
  return check_report("test_scalpel");
}
