/* SPDX-License-Identifier: Apache-2.0 */
/* Topology changes in the live runtime (topology_follow.h): a probe pressing
 * into the adaptive kidney (assets/scenes/kidney_adaptive.yaml) keeps its
 * contact and its force does not jump when the mesh refines under it,
 * simplifies under it (still pressing) or re-centres as it slides; after
 * every change the rebuilt tree answers nearest-point queries exactly like a
 * brute-force scan of the new surface, the surface view and the contact
 * patch refer to the new mesh, and steps without a change reuse the tree. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_assets.h"
#include "test_runtime.h"
#include "physics/adaptive.h"
#include "runtime/scene_runtime.h"
#include "runtime/topology_follow.h"
#include "vmath.h"

/* Largest change of the contact force (N) over the step in which the
 * topology changes: the re-attachment keeps the proxy where it was, so only
 * the device motion (<= 10 um per step here, 4 mN at 400 N/m) and the
 * step's own physics remain (the coarse model changes its force by < 9 mN
 * per step on this path). Without the settling offset a simplification
 * under load steps the force by 0.5 N here (the refined dent disappears).
 * What the model does in the steps after a change is its own dynamics: the
 * new light nodes of a refinement start out of equilibrium and the refined
 * region is locally softer, so the force moves by up to ~0.3 N per step for
 * a few steps (printed, bounded only loosely by DYNAMICS_BOUND: no blow-up). */
#define JUMP_BOUND 0.02
#define DYNAMICS_BOUND 0.6

static runtime_t rt;
static scene_t sc;
static uint32_t seen_version;
static int changes_seen, contact_lost;
static double worst_jump, worst_jump_force, worst_step;
static unsigned long long worst_step_at;

/* Nearest surface point of every query: tree against a scan of the
 * model's current triangles, same per-triangle test. */
static void check_tree_of(const organ_rt_t *o, const runtime_t *rtp) {
  const model_t *m = o->model;
  CHECK(o->tree.ntris == m->nsurf_tris && o->tree.nverts == m->nsurf);
  CHECK(rtp->surfaces[0].tris == m->surf_tris && rtp->surfaces[0].ntris == m->nsurf_tris &&
        rtp->surfaces[0].x == m->surf_x && rtp->surfaces[0].tree == &o->tree);
  srand(7 + (unsigned)m->topology_version);
  int mismatches = 0;
  for (int q = 0; q < 300; q++) {
    double p[3];
    for (int k = 0; k < 3; k++)
      p[k] = o->tree.lo[k] - 0.01 + (o->tree.hi[k] - o->tree.lo[k] + 0.02) * rand() / RAND_MAX;
    aabb_nearest_t r;
    if (!aabb_tree_nearest(&o->tree, p, INFINITY, &r)) {
      mismatches++;
      continue;
    }
    double best = INFINITY;
    for (size_t t = 0; t < m->nsurf_tris; t++) {
      const uint32_t *tri = m->surf_tris + 3 * t;
      double cp[3], b[3];
      tri_closest_point(p, m->surf_x + 3 * tri[0], m->surf_x + 3 * tri[1], m->surf_x + 3 * tri[2], cp, b);
      double d[3];
      v3_sub(d, cp, p);
      best = fmin(best, v3_dot(d, d));
    }
    if (!(fabs(best - r.dist2) <= 1e-15 * fmax(best, 1e-12))) mismatches++;
  }
  CHECK(mismatches == 0);
}

static void check_tree(const organ_rt_t *o) { check_tree_of(o, &rt); }

static void check_contact_refs(void) {
  const tool_rt_t *tool = &rt.tools[0];
  const model_t *m = rt.organs[0].model;
  CHECK(tool->proxy.tri < m->nsurf_tris);
  int patch_ok = tool->npatch > 0;
  for (size_t j = 0; j < tool->npatch; j++) patch_ok &= tool->patch[j] < m->nsurf;
  CHECK(patch_ok);
}

/* One step with the device at pos; checks what a topology change did. */
static double step_at(const double pos[3], double *prev_force) {
  runtime_set_tool(&rt, 0, pos, 4.0);
  int was_contact = rt.tools[0].proxy.in_contact;
  runtime_step(&rt);
  const organ_rt_t *o = &rt.organs[0];
  double f = v3_norm(rt.tools[0].force);
  if (was_contact && !rt.tools[0].proxy.in_contact) contact_lost++;
  if (was_contact && fabs(f - *prev_force) > worst_step) {
    worst_step = fabs(f - *prev_force);
    worst_step_at = rt.steps;
  }
  CHECK(o->topology_version == o->model->topology_version);
  if (o->topology_version != seen_version) {
    seen_version = o->topology_version;
    changes_seen++;
    double jump = fabs(f - *prev_force);
    printf("step %llu: topology %u, %zu vertices / %zu triangles, force %.4f -> %.4f N (jump %.2g N), rebuild %.0f "
           "us\n",
           (unsigned long long)rt.steps, o->topology_version, o->model->nsurf, o->model->nsurf_tris, *prev_force, f,
           jump, o->last_follow_us);
    if (jump > worst_jump) {
      worst_jump = jump;
      worst_jump_force = f;
    }
    CHECK(rt.tools[0].proxy.in_contact);
    CHECK(jump <= JUMP_BOUND);
    check_tree(o);
    check_contact_refs();
  }
  *prev_force = f;
  return f;
}

/* The path a cutting model takes (no coarse-face mapping): topo_follow with
 * anchors that carry no face re-attaches by the nearest point on the same
 * side. Driven by hand on the adaptive kidney: the probe presses with
 * refinement off, then the surface is refined / simplified directly and the
 * model's counts updated the way a model does before it bumps its version. */
static void test_generic_reattach(void) {
  static scene_t sc2;
  static runtime_t r2;
  verr_t err;
  if (!test_runtime_load_scene(&r2, &sc2, "kidney_adaptive.yaml", &err)) {
    CHECK(!"adaptive scene loads");
    return;
  }
  model_t *m = r2.organs[0].model;
  adaptive_model_t *am = model_adaptive_of(m);
  am->ad.p.refine_levels = 0; /* this test changes the topology itself */
  double dev[3] = {0.012, 0.004, 0.040};
  for (int s = 0; s < 1500; s++) {
    if (dev[2] > 0.029) dev[2] -= 2e-5;
    runtime_set_tool(&r2, 0, dev, 4.0);
    runtime_step(&r2);
  }
  proxy_t *p = &r2.tools[0].proxy;
  CHECK(p->in_contact && m->topology_version == 0);
  double f0 = v3_norm(r2.tools[0].force);
  for (int change = 0; change < 2; change++) {
    topo_anchor_t anchors[SCENE_MAX_TOOLS];
    topo_capture(&r2, 0, anchors);
    anchors[0].face = UINT32_MAX; /* as for a model without the mapping */
    double before[3], n_before[3];
    v3_copy(before, p->pos);
    v3_copy(n_before, p->normal);
    if (change == 0) {
      am->ad.p.refine_levels = 2;
      CHECK(adaptive_refine(&am->ad, am->ad.tris[3 * p->tri]) == 0);
    } else {
      adaptive_simplify(&am->ad);
    }
    m->nnodes = m->nsurf = am->ad.n;
    m->nsurf_tris = am->ad.nt;
    m->topology_version = am->ad.topology_version;
    CHECK(topo_follow(&r2, 0, anchors, &err) == 0);
    CHECK(r2.organs[0].topology_version == m->topology_version && r2.surfaces[0].ntris == m->nsurf_tris);
    CHECK(p->in_contact && p->tri < m->nsurf_tris && v3_dist(p->pos, before) < 1e-12);
    CHECK(v3_dot(p->normal, n_before) > 0.9);
    /* The point the proxy re-attached to is the surface point nearest to
     * where it was; refinement keeps the surface, so it is the same point. */
    double settle = v3_norm(p->settle);
    if (change == 0) CHECK(settle < 1e-9);
    printf("generic re-attach after %s: triangle %u, settling offset %.3g m\n",
           change ? "simplification" : "refinement", p->tri, settle);
    check_tree_of(&r2.organs[0], &r2);
    double f1 = v3_norm(r2.tools[0].force);
    runtime_step(&r2);
    CHECK(p->in_contact);
    printf("  force %.4f N before, %.4f N one step after\n", f1, v3_norm(r2.tools[0].force));
  }
  CHECK(f0 > 0.2);
  runtime_destroy(&r2);
}

int main(void) {
  const char *src = getenv("VISCERA_SOURCE_DIR");
  if (!src) {
    CHECK(!"VISCERA_SOURCE_DIR set");
    return check_report("test_topology_runtime");
  }
  if (!test_runtime_load_scene(&rt, &sc, "kidney_adaptive.yaml", NULL)) {
    CHECK(!"adaptive scene loads into the runtime");
    return check_report("test_topology_runtime");
  }
  organ_rt_t *o = &rt.organs[0];
  adaptive_model_t *am = model_adaptive_of(o->model);
  CHECK(am != NULL && o->topology_version == 0);
  if (!am) return check_report("test_topology_runtime");
  const size_t n0 = o->model->nsurf;
  check_tree(o);

  /* a. Refinement under load: refine only once the largest force on one
   * node reaches 0.2 N (about 0.8 N on the probe, spread over the patch),
   * then keep the default so the refinement stays. */
  am->ad.p.refine_force = 0.2;
  double dev[3] = {0.012, 0.004, 0.045}, fprev = 0, f = 0;
  const aabb_node_t *nodes = o->tree.nodes;
  int reused = 1;
  for (int s = 0; s < 2000 && o->topology_version == 0; s++) {
    dev[2] -= 1e-5; /* 10 mm/s */
    f = step_at(dev, &fprev);
    if (o->topology_version == 0) reused &= o->tree.nodes == nodes;
  }
  CHECK(reused); /* no change, no rebuild */
  CHECK(o->topology_version == 1 && o->model->nsurf > n0 && f >= 0.25);
  double f_refined = f;
  am->ad.p.refine_force = ADAPT_DEFAULT_REFINE_FORCE;
  /* A proxy on a refined face sits on one of its pieces now. */
  CHECK(adaptive_tri_face(&am->ad, rt.tools[0].proxy.tri) != ADAPT_NONE);
  for (int s = 0; s < 100; s++) step_at(dev, &fprev);

  /* b. Simplification while still pressing: no step reaches the refine
   * force, so after release_time the coarse mesh returns. */
  am->ad.p.refine_force = 1e3;
  for (int s = 0; s < 200 && o->topology_version == 1; s++) f = step_at(dev, &fprev);
  CHECK(o->topology_version == 2 && o->model->nsurf == n0 && f > 0.2);
  double f_simplified = f;
  for (int s = 0; s < 50; s++) step_at(dev, &fprev);

  /* c. Refinement again at once, then a slow slide re-centres it. */
  am->ad.p.refine_force = ADAPT_DEFAULT_REFINE_FORCE;
  step_at(dev, &fprev);
  CHECK(o->topology_version == 3 && o->model->nsurf > n0);
  for (int s = 0; s < 1500; s++) {
    dev[0] += 5e-6; /* 5 mm/s along x */
    step_at(dev, &fprev);
  }
  CHECK(o->topology_version >= 5 && (o->topology_version & 1)); /* re-centred: simplify + refine, still refined */
  CHECK(contact_lost == 0 && worst_step <= DYNAMICS_BOUND);

  /* d. Lift off: contact ends, the mesh simplifies after release_time. */
  uint32_t before_lift = o->topology_version;
  for (int s = 0; s < 400; s++) {
    dev[2] += 1e-4;
    runtime_set_tool(&rt, 0, dev, 4.0);
    runtime_step(&rt);
  }
  CHECK(!rt.tools[0].proxy.in_contact && o->topology_version == before_lift + 1 && o->model->nsurf == n0);
  check_tree(o);
  CHECK(o->topology_changes == (uint64_t)changes_seen + 1); /* a re-centre is one rebuild for two versions */

  printf("%d topology changes under the probe, contact kept through all; force at refinement %.3f N, at "
         "simplification %.3f N; largest force jump at a change %.2g N (at %.3f N), largest step-to-step change in "
         "contact %.2g N at step %llu (bounds %.2g N at a change, %.2g N any step)\n",
         changes_seen, f_refined, f_simplified, worst_jump, worst_jump_force, worst_step, worst_step_at, JUMP_BOUND,
         DYNAMICS_BOUND);
  runtime_destroy(&rt);
  test_generic_reattach();
  return check_report("test_topology_runtime");
}
