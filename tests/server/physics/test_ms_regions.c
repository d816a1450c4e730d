/* SPDX-License-Identifier: Apache-2.0 */
/* test_ms_regions: regional sleeping of the surface mass-spring model
 * (server/physics/ms_regions.h), judged by counters and states, never time.
 *
 * - A held press on a 40 x 40 sheet: far nodes never integrated, bit for
 *   bit at rest (no drift while asleep); the pressed node's displacement
 *   matches the model with regions off within 0.5 %.
 * - A force far away wakes what it touches (integrated in that step).
 * - A write from outside (a reset of a sleeping node) is seen: rebuilt,
 *   integrated, back at rest.
 * - A topology change rebuilds; a copy of the state in a fresh model
 *   continues bit for bit (what a checkpoint restore relies on).
 * - Through the runtime: the probe pressing the gallbladder integrates a
 *   small share of the nodes, and its force matches regions off (RMS over
 *   the press <= 0.5 % of the peak). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "mesh.h"
#include "physics/model.h"
#include "physics/model_mass_spring.h"
#include "physics/ms_regions.h"
#include "runtime/scene_runtime.h"
#include "scene.h"
#include "test_runtime.h"
#include "vmath.h"

#define G 40 /* sheet of G x G nodes, 2 mm apart */

static void sheet(mesh_t *m) {
  verr_t err;
  CHECK(mesh_alloc(m, G * G, 2 * (G - 1) * (G - 1), &err) == 0);
  for (int r = 0; r < G; r++)
    for (int c = 0; c < G; c++) {
      double *p = m->pos + 3 * (r * G + c);
      p[0] = 0.002 * c;
      p[1] = 0.002 * r;
      p[2] = 0;
    }
  size_t t = 0;
  for (int r = 0; r + 1 < G; r++)
    for (int c = 0; c + 1 < G; c++) {
      uint32_t a = (uint32_t)(r * G + c), b = a + 1, d = a + G, e = d + 1;
      uint32_t *q = m->tris + 6 * t++;
      q[0] = a, q[1] = b, q[2] = e, q[3] = a, q[4] = e, q[5] = d;
    }
}

static scene_organ_t organ(const char *extra) {
  static scene_t sc;
  char yaml[1024];
  verr_t err;
  snprintf(yaml, sizeof yaml, "scene: t\norgans:\n  - name: sheet\n    mesh: none.obj\n%s", extra);
  if (scene_load_string(yaml, "t.yaml", NULL, &sc, &err)) {
    fprintf(stderr, "  %s\n", err.msg);
    CHECK(!"organ yaml loads");
  }
  return sc.organs[0];
}

static model_t *make(const scene_organ_t *cfg, const mesh_t *surf) {
  verr_t err;
  model_params_t p = {.cfg = cfg, .surface = surf, .gravity = {0, 0, 0}, .dt = 1e-3, .tool_stiffness = 0};
  model_t *m = model_create(&p, &err);
  if (!m) fprintf(stderr, "  %s\n", err.msg);
  CHECK(m != NULL);
  return m;
}

/* The hook: 20 mN down at node `push` (and `push2` when set), every sub-step. */
static uint32_t push = G / 2 * G + G / 2, push2 = UINT32_MAX;
static void press_hook(model_t *m, void *ctx) {
  (void)ctx;
  const double f[3] = {0, 0, -0.02};
  m->ops->add_surface_force(m, push, f);
  if (push2 != UINT32_MAX) m->ops->add_surface_force(m, push2, f);
}

/* The nodes integrated at least once since `since` was cleared. */
static void mark_updated(const model_t *m, uint8_t *since) {
  const ms_regions_t *r = model_mass_spring_regions(m);
  if (!r) return;
  for (size_t k = 0; k < r->n; k++) since[k] |= r->awake[k] | r->held[k];
}

static void test_sheet(void) {
  mesh_t s;
  sheet(&s);
  scene_organ_t on = organ(""), off = organ("    solver: {region_force: 0}\n");
  CHECK(on.solver.region_force == SCENE_REGION_FORCE && off.solver.region_force == 0);
  model_t *a = make(&on, &s), *b = make(&off, &s);
  if (!a || !b) return;
  ms_region_counts_t c0, c1;
  CHECK(model_mass_spring_region_counts(a, &c0) == 0);
  CHECK(model_mass_spring_region_counts(b, &c0) == -1); /* off: no regions */
  a->hook = b->hook = press_hook;
  static uint8_t ever[G * G];
  memset(ever, 0, sizeof ever);
  int ok = 1;
  for (int step = 0; step < 400; step++) {
    ok &= a->ops->step(a, 1e-3) == 0 && b->ops->step(b, 1e-3) == 0;
    mark_updated(a, ever);
  }
  CHECK(ok);
  /* The press settled: the pressed node where regions-off has it. */
  double da = a->x_rest[3 * push + 2] - a->x[3 * push + 2], db = b->x_rest[3 * push + 2] - b->x[3 * push + 2];
  printf("sheet: pressed node down %.6g mm (regions) vs %.6g mm (off)\n", 1e3 * da, 1e3 * db);
  CHECK(db > 1e-4 && fabs(da - db) <= 0.005 * db);
  CHECK(model_mass_spring_region_counts(a, &c1) == 0);
  size_t never = 0, drift = 0;
  for (size_t k = 0; k < (size_t)G * G; k++) {
    if (ever[k]) continue;
    never++;
    if (memcmp(a->x + 3 * k, a->x_rest + 3 * k, 3 * sizeof(double)) || a->v[3 * k] != 0 || a->v[3 * k + 1] != 0 ||
        a->v[3 * k + 2] != 0)
      drift++;
  }
  double share = (double)c1.node_updates / ((double)c1.substeps * (double)c1.nodes);
  printf("sheet: %zu of %d nodes never integrated, %.2f %% node updates per sub-step, %zu awake now\n", never, G * G,
         100 * share, c1.awake);
  CHECK(never > (size_t)G * G / 4); /* the far part of the sheet slept all along */
  CHECK(drift == 0);                /* and did not move by a bit */
  CHECK(share < 0.25);
  CHECK(c1.awake < (size_t)G * G / 4);

  /* A force far away (the opposite corner, asleep) wakes it in that step. */
  const ms_regions_t *r = model_mass_spring_regions(a);
  CHECK(r && !r->awake[0]);
  push2 = 0;
  double z0 = a->x[2];
  CHECK(a->ops->step(a, 1e-3) == 0 && b->ops->step(b, 1e-3) == 0);
  CHECK(r->awake[0] && a->x[2] < z0);
  for (int step = 0; step < 300; step++) CHECK(a->ops->step(a, 1e-3) == 0 && b->ops->step(b, 1e-3) == 0);
  printf("sheet: corner down %.6g mm (regions) vs %.6g mm (off)\n", 1e3 * (a->x_rest[2] - a->x[2]),
         1e3 * (b->x_rest[2] - b->x[2]));
  CHECK(fabs((a->x_rest[2] - a->x[2]) - (b->x_rest[2] - b->x[2])) <= 0.005 * (b->x_rest[2] - b->x[2]));
  push2 = UINT32_MAX;

  /* Steps with nothing written from outside never look at the sleeping
   * nodes (the pass over the organ is what regional sleeping saves). */
  size_t far = (size_t)G * (G - 1) + G - 1; /* the far corner */
  CHECK(!r->awake[far]);
  CHECK(model_mass_spring_region_counts(a, &c0) == 0);
  for (int step = 0; step < 20; step++) CHECK(a->ops->step(a, 1e-3) == 0);
  CHECK(model_mass_spring_region_counts(a, &c1) == 0);
  CHECK(c1.sleeper_checks == c0.sleeper_checks && c1.builds == c0.builds);
  /* A sleeping node moved from outside (a reset of one node), noted as
   * model.h asks: seen at the next step, integrated, and back home. */
  CHECK(!r->awake[far]);
  c0 = c1;
  a->x[3 * far + 2] += 0.001;
  model_note_outside_write(a);
  CHECK(a->ops->step(a, 1e-3) == 0);
  CHECK(model_mass_spring_region_counts(a, &c1) == 0);
  CHECK(c1.sleeper_checks == c0.sleeper_checks + 1);
  CHECK(c1.builds == c0.builds + 1 && r->awake[far]);
  /* A write noted that changed no sleeping node: looked at, nothing rebuilt. */
  c0 = c1;
  model_note_outside_write(a);
  CHECK(a->ops->step(a, 1e-3) == 0);
  CHECK(model_mass_spring_region_counts(a, &c1) == 0);
  CHECK(c1.sleeper_checks == c0.sleeper_checks + 1 && c1.builds == c0.builds);
  for (int step = 0; step < 2000; step++) a->ops->step(a, 1e-3);
  CHECK(fabs(a->x[3 * far + 2] - a->x_rest[3 * far + 2]) < 1e-6);

  /* A copy of the state in a fresh model continues bit for bit. */
  model_t *c = make(&on, &s);
  if (c) {
    c->hook = press_hook;
    memcpy(c->x, a->x, 3 * a->nnodes * sizeof(double));
    memcpy(c->v, a->v, 3 * a->nnodes * sizeof(double));
    model_note_outside_write(c);
    int same = 1;
    for (int step = 0; step < 200; step++) {
      CHECK(a->ops->step(a, 1e-3) == 0 && c->ops->step(c, 1e-3) == 0);
      same &=
          !memcmp(a->x, c->x, 3 * a->nnodes * sizeof(double)) && !memcmp(a->v, c->v, 3 * a->nnodes * sizeof(double));
    }
    CHECK(same);
    model_destroy(c);
  }

  /* A topology change (the same triangles committed again, as a cut does
   * with new ones) rebuilds at the next step. */
  const model_edit_ops_t *ed = a->ops->edit;
  CHECK(ed != NULL);
  if (ed) {
    verr_t err;
    uint32_t map[G * G];
    for (uint32_t k = 0; k < G * G; k++) map[k] = k;
    model_topology_t t = {.n = G * G, .old_to_new = map, .old_n = G * G, .ntris = s.ntris, .tris = s.tris};
    CHECK(model_mass_spring_region_counts(a, &c0) == 0);
    CHECK(ed->commit(a, &t, &err) == 0);
    CHECK(a->ops->step(a, 1e-3) == 0);
    CHECK(model_mass_spring_region_counts(a, &c1) == 0);
    CHECK(c1.builds == c0.builds + 1);
  }
  model_destroy(a);
  model_destroy(b);
  mesh_free(&s);
}

/* The probe (400 N/m) presses the gallbladder's top to 1 N and holds:
 * force per step into f[]; returns the share of nodes integrated per
 * sub-step (regions on) or -1. */
static double probe_press(const char *keys, double *f, int n) {
  static scene_t sc;
  static runtime_t rt;
  if (!test_runtime_one_organ(&rt, &sc, "regions", "gallbladder.obj", keys,
                              "radius: 0.003, stiffness: 400, max_force: 4", NULL))
    return -2;
  const model_t *m = rt.organs[0].model;
  size_t top = 0;
  for (size_t i = 1; i < m->nsurf; i++)
    if (m->surf_rest[3 * i + 2] > m->surf_rest[3 * top + 2]) top = i;
  double p[3];
  v3_copy(p, m->surf_rest + 3 * top);
  p[2] += 0.002;
  int pressing = 1;
  for (int s = 0; s < n; s++) {
    if (pressing && s < 200) p[2] -= 5e-5;
    runtime_set_tool(&rt, 0, p, 100);
    runtime_step(&rt);
    f[s] = v3_norm(rt.tools[0].force);
    if (f[s] >= 1.0) pressing = 0;
  }
  ms_region_counts_t c;
  double share = model_mass_spring_region_counts(m, &c) == 0
                     ? (double)c.node_updates / ((double)c.substeps * (double)c.nodes)
                     : -1;
  runtime_destroy(&rt);
  return share;
}

static void test_probe(void) {
  enum { N = 300 };
  static double fa[N], fb[N];
  double sa = probe_press("", fa, N), sb = probe_press("    solver: {region_force: 0}\n", fb, N);
  CHECK(sa >= 0 && sb == -1);
  double e2 = 0, peak = 0;
  for (int i = 0; i < N; i++) {
    e2 += (fa[i] - fb[i]) * (fa[i] - fb[i]);
    peak = fmax(peak, fb[i]);
  }
  double rel = sqrt(e2 / N) / peak;
  printf("gallbladder press: peak %.4f N, RMS force error %.3g of the peak, %.2f %% node updates per sub-step\n", peak,
         rel, 100 * sa);
  CHECK(peak > 0.9);
  CHECK(rel <= 0.005);
  CHECK(sa < 0.25);
}

int main(void) {
  test_sheet();
  test_probe();
  return check_report("test_ms_regions");
}
