/* SPDX-License-Identifier: Apache-2.0 */
/* test_tool_actions: grasping, stones, tool-tool contact and tasks on the
 * real runtime (kidney mesh, mass-spring model), no networking:
 * - grasp_take / grasp_force: weights, nearest vertices, clamp, direction;
 * - winding number inside / outside the kidney;
 * - grasp, hold, pull, release: the grasped vertex follows the tool up,
 *   the tool is pulled back down, opening releases and the tissue returns;
 *   a tool released by the runtime (client lost) lets go too;
 * - stone removal: the extractor takes the stone, carries it out, the
 *   task completes with its operation time; a stone left inside does not;
 * - two tools driven to the same point keep their tips r1 + r2 apart and
 *   feel opposite forces;
 * - a shaft laid on the tissue presses it and is pushed back;
 * - a shaft crossing a coarse triangle between its corners (tissue_block)
 *   pushes that triangle in and is pushed back (segment-triangle test). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_assets.h"
#include "test_runtime.h"
#include "interaction/grasp.h"
#include "interaction/stone.h"
#include "runtime/scene_runtime.h"
#include "vmath.h"

static runtime_t rt; /* large */
static scene_t sc;

static int load(const char *yaml) { return test_runtime_load(&rt, &sc, yaml, NULL); }

static int count_events(iev_kind_t kind) {
  int n = 0;
  for (size_t i = 0; i < rt.events.n; i++) n += rt.events.ev[i].kind == kind;
  return n;
}

/* Steps n times with tool t moving linearly from a to b. */
static void drive(size_t t, const double a[3], const double b[3], int n) {
  for (int i = 1; i <= n; i++) {
    double p[3];
    for (int k = 0; k < 3; k++) p[k] = a[k] + (b[k] - a[k]) * i / n;
    runtime_set_tool(&rt, t, p, 4);
    runtime_step(&rt);
  }
}

static void test_grasp_unit(void) {
  /* A 5 x 5 grid with 1 mm spacing in z = 0. */
  double x[75];
  for (int i = 0; i < 25; i++) v3_set(x + 3 * i, 0.001 * (i % 5), 0.001 * (i / 5), 0);
  grasp_t g;
  double tip[3] = {0.002, 0.002, 0.0005};
  CHECK(grasp_take(&g, 0, x, 25, tip, 0.0001) == 0 && !g.active); /* nothing within 0.1 mm */
  size_t n = grasp_take(&g, 0, x, 25, tip, 0.0013);
  CHECK(n == 5 && g.active); /* the centre and its 4 neighbours */
  double sum = 0;
  for (size_t j = 0; j < n; j++) sum += g.w[j];
  CHECK_NEAR(sum, 1, 1e-12);
  n = grasp_take(&g, 0, x, 25, tip, 0.01);
  CHECK(n == GRASP_MAX_VERTS); /* 25 qualify, the nearest 16 are kept */
  double fv[GRASP_MAX_VERTS][3], ft[3];
  CHECK_NEAR(grasp_force(&g, x, tip, 400, 4, fv, ft), 0, 1e-12); /* not moved: no force */
  double up[3] = {tip[0], tip[1], tip[2] + 0.001};
  double mag = grasp_force(&g, x, up, 400, 4, fv, ft);
  CHECK_NEAR(mag, 0.4, 1e-9);       /* k * 1 mm, weights sum to 1 */
  CHECK(ft[2] < 0 && fv[0][2] > 0); /* the tool is pulled down, the tissue up */
  double far[3] = {tip[0], tip[1], tip[2] + 0.1};
  CHECK_NEAR(grasp_force(&g, x, far, 400, 4, fv, ft), 4, 1e-9); /* clamped */
  grasp_release(&g);
  CHECK(!g.active && grasp_force(&g, x, far, 400, 4, fv, ft) == 0);
}

#define KIDNEY "scene: t\norgans:\n  - {name: kidney, mesh: ../meshes/kidney.obj, material: {mass: 0.15}}\n"

static void test_winding(void) {
  CHECK(load(KIDNEY));
  const model_t *m = rt.organs[0].model;
  double in[3] = {0, 0, 0.017}, out[3] = {0, 0, 0.06}, side[3] = {0.2, 0, 0.01};
  CHECK_NEAR(stone_winding_number(m->surf_rest, m->surf_tris, m->nsurf_tris, in), 1, 1e-6);
  CHECK_NEAR(stone_winding_number(m->surf_rest, m->surf_tris, m->nsurf_tris, out), 0, 1e-6);
  CHECK_NEAR(stone_winding_number(m->surf_rest, m->surf_tris, m->nsurf_tris, side), 0, 1e-6);
  CHECK_NEAR(stone_surface_distance(m->surf_rest, m->surf_tris, m->nsurf_tris, out), 0.06 - 0.035, 1e-3);
  runtime_destroy(&rt);
  /* A stone placed outside its organ is refused with the line. */
  verr_t e;
  CHECK(scene_load_string(KIDNEY "objects:\n  - {name: s, radius: 0.004, position: [0, 0, 0.06], organ: kidney}\n",
                          "t.yaml", getenv("VISCERA_SOURCE_DIR") ? "" : ".", &sc, &e) == 0);
  CHECK(scene_load_string(KIDNEY "objects:\n  - {name: s, radius: 0.004, position: [0, 0, 0.06], organ: kidney}\n",
                          "t.yaml", test_asset("scenes"), &sc, &e) == 0);
  CHECK(runtime_init(&rt, &sc, &e) != 0 && strstr(e.msg, "t.yaml:5: object 's'") && strstr(e.msg, "not inside"));
}

static void test_grasp_pull_release(int lose_client) {
  CHECK(load(KIDNEY "tools:\n  - {name: g, kind: grasper, radius: 0.002, grasp_radius: 0.004, stiffness: 400}\n"
                    "tasks:\n  - {name: lift, kind: grasp_pull, tool: g, distance: 0.01}\n"));
  const model_t *m = rt.organs[0].model;
  double above[3] = {0.012, 0.004, 0.06}, at[3] = {0.012, 0.004, 0.035}, lifted[3] = {0.012, 0.004, 0.047};
  /* The surface vertex nearest the grasp point. */
  size_t vi = 0;
  for (size_t i = 1; i < m->nsurf; i++)
    if (v3_dist(m->surf_rest + 3 * i, at) < v3_dist(m->surf_rest + 3 * vi, at)) vi = i;
  double z0 = m->surf_rest[3 * vi + 2];
  drive(0, above, at, 300);
  CHECK(!rt.tools[0].grasp.active); /* open jaws take nothing */
  runtime_set_buttons(&rt, 0, 1);
  drive(0, at, at, 20);
  CHECK(rt.tools[0].grasp.active && rt.tools[0].grasp.n >= 2);
  CHECK(count_events(IEV_GRASP_BEGIN) == 1 && count_events(IEV_TASK_STARTED) == 1);
  int held = 0;
  for (size_t j = 0; j < rt.tools[0].grasp.n; j++) held |= rt.tools[0].grasp.v[j] == vi;
  CHECK(held);
  drive(0, at, lifted, 1000);
  drive(0, lifted, lifted, 200);
  double dz = m->surf_x[3 * vi + 2] - z0;
  printf("grasp: %zu vertices held, nearest vertex lifted %.2f mm by a 12 mm pull, tool force %.3f N (z %.3f)\n",
         rt.tools[0].grasp.n, dz * 1e3, v3_norm(rt.tools[0].force), rt.tools[0].force[2]);
  CHECK(dz > 0.006);                  /* the tissue followed the tool */
  CHECK(rt.tools[0].force[2] < -0.1); /* and pulls it back down */
  CHECK(rt.tools[0].fb_contact == 1 && rt.tools[0].fb_organ == 0);
  CHECK(count_events(IEV_TASK_COMPLETED) == 1);
  CHECK(rt.tasks[0].completed && rt.tasks[0].t_end - rt.tasks[0].t_start > 1.0);
  if (lose_client) {
    runtime_release_tool(&rt, 0);
    CHECK(!rt.tools[0].grasp.active);
    for (int i = 0; i < 1000; i++) runtime_step(&rt);
  } else {
    runtime_set_buttons(&rt, 0, 0);
    drive(0, lifted, lifted, 1000);
    CHECK(!rt.tools[0].grasp.active && v3_norm(rt.tools[0].force) < 1e-9);
  }
  CHECK(count_events(IEV_GRASP_END) == 1);
  double back = m->surf_x[3 * vi + 2] - z0;
  printf("grasp: %s, after 1 s the vertex is %.3f mm from rest\n", lose_client ? "client lost" : "released",
         back * 1e3);
  CHECK(fabs(back) < 0.001); /* the tissue went home */
  runtime_destroy(&rt);
}

static void test_stone(int carry_out) {
  CHECK(load(KIDNEY "tools:\n  - {name: x, kind: extractor, radius: 0.0015, grasp_radius: 0.003, stiffness: 300}\n"
                    "objects:\n  - {name: s, radius: 0.004, position: [-0.015, 0, 0.016], organ: kidney}\n"
                    "tasks:\n  - {name: out, kind: stone_removal, tool: x, object: s}\n"));
  double above[3] = {-0.015, 0, 0.07}, over[3] = {-0.015, 0, 0.021}, inside[3] = {-0.015, 0, 0.024};
  drive(0, above, over, 500);
  /* The extractor passes through tissue: no proxy contact on the way in. */
  CHECK(!rt.tools[0].proxy.in_contact && rt.stones[0].held_by < 0);
  runtime_set_buttons(&rt, 0, 1);
  drive(0, over, over, 10);
  CHECK(rt.stones[0].held_by == 0 && count_events(IEV_GRASP_BEGIN) == 1);
  double peak = 0;
  const double *target = carry_out ? above : inside;
  for (int i = 1; i <= 1500; i++) {
    double p[3];
    for (int k = 0; k < 3; k++) p[k] = over[k] + (target[k] - over[k]) * i / 1500;
    runtime_set_tool(&rt, 0, p, 4);
    runtime_step(&rt);
    peak = fmax(peak, v3_norm(rt.tools[0].force));
  }
  CHECK_NEAR(rt.stones[0].pos[2], target[2] - 0.005, 1e-9); /* it followed at its grab offset */
  runtime_set_buttons(&rt, 0, 0);
  drive(0, target, target, 10);
  CHECK(rt.stones[0].held_by < 0 && count_events(IEV_GRASP_END) == 1);
  printf("stone: %s, peak force on the extractor %.3f N, removed %d, operation time %.3f s\n",
         carry_out ? "carried out" : "moved inside", peak, rt.stones[0].removed,
         rt.tasks[0].t_end - rt.tasks[0].t_start);
  if (carry_out) {
    CHECK(peak > 0.01); /* the tissue resisted on the way out */
    CHECK(rt.stones[0].removed && rt.tasks[0].completed && count_events(IEV_TASK_COMPLETED) == 1);
    /* Out when the centre passed the top (3.5 cm) by the radius: 0.51 s to
     * reach and close, then about 0.7 s of the 1.5 s carry. */
    CHECK(rt.tasks[0].t_end - rt.tasks[0].t_start > 1.0 && rt.tasks[0].t_end - rt.tasks[0].t_start < 1.5);
  } else {
    CHECK(!rt.stones[0].removed && !rt.tasks[0].completed && count_events(IEV_TASK_COMPLETED) == 0);
  }
  runtime_destroy(&rt);
}

static void test_tool_tool(void) {
  CHECK(load(KIDNEY "tools:\n  - {name: a, radius: 0.003, stiffness: 400}\n  - {name: b, radius: 0.004, "
                    "stiffness: 300}\n"));
  /* Driven towards each other until the devices are 1 mm apart. */
  double pa[3] = {0.0, 0.0, 0.08}, pb[3] = {0.02, 0.0, 0.08}, ma[3] = {0.0095, 0.0, 0.08}, mb[3] = {0.0105, 0, 0.08};
  double min_d = INFINITY;
  for (int i = 1; i <= 200; i++) {
    double a[3], b[3];
    for (int k = 0; k < 3; k++) {
      a[k] = pa[k] + (ma[k] - pa[k]) * i / 200;
      b[k] = pb[k] + (mb[k] - pb[k]) * i / 200;
    }
    runtime_set_tool(&rt, 0, a, 4);
    runtime_set_tool(&rt, 1, b, 4);
    runtime_step(&rt);
    min_d = fmin(min_d, v3_dist(rt.tools[0].fb_pos, rt.tools[1].fb_pos));
  }
  printf("tool-tool: devices 1 mm apart, tips %.4f mm apart (radii sum 7 mm), forces %.3f / %.3f N\n", min_d * 1e3,
         rt.tools[0].force[0], rt.tools[1].force[0]);
  CHECK(min_d >= 0.007 - 1e-9);
  CHECK(rt.tools[0].fb_contact && rt.tools[1].fb_contact && rt.tools[0].fb_organ == -1);
  CHECK(rt.tools[0].force[0] < -0.5 && rt.tools[1].force[0] > 0.5); /* pushed apart */
  CHECK(v3_norm(rt.tools[0].force) <= 4 + 1e-9);
  runtime_destroy(&rt);
}

/* A probe laid flat (axis +x) with its shaft 1 mm above the kidney's top:
 * the shaft (radius 0.45 x 3 mm) presses the surface down and is pushed up;
 * held upright at the same place the shaft touches nothing. */
static void test_shaft(void) {
  CHECK(load(KIDNEY "tools:\n  - {name: a, radius: 0.003, length: 0.1, stiffness: 400}\n"));
  const model_t *m = rt.organs[0].model;
  double top[3] = {0.012, 0.004, 0.0346};
  size_t vi = 0;
  for (size_t i = 1; i < m->nsurf; i++)
    if (v3_dist(m->surf_rest + 3 * i, top) < v3_dist(m->surf_rest + 3 * vi, top)) vi = i;
  double vz = m->surf_rest[3 * vi + 2];
  /* Tip well outside the kidney (x < -0.055), axis along +x over the top. */
  double tip[3] = {-0.07, m->surf_rest[3 * vi + 1], vz + 0.001};
  const double flat[4] = {sqrt(0.5), 0, sqrt(0.5), 0}; /* +z turned to +x about y */
  runtime_set_orientation(&rt, 0, flat);
  CHECK_NEAR(rt.tools[0].axis[0], 1, 1e-12);
  drive(0, tip, tip, 300);
  double dz = m->surf_x[3 * vi + 2] - vz;
  printf("shaft: laid 1 mm above the surface, the vertex below sinks %.3f mm, the tool is pushed up %.3f N\n",
         -dz * 1e3, rt.tools[0].force[2]);
  CHECK(dz < -0.0001);
  CHECK(rt.tools[0].force[2] > 0.05 && rt.tools[0].fb_contact && rt.tools[0].fb_organ == 0);
  CHECK(!rt.tools[0].proxy.in_contact); /* the tip itself touches nothing */
  const double upright[4] = {1, 0, 0, 0};
  runtime_set_orientation(&rt, 0, upright);
  drive(0, tip, tip, 1000);
  CHECK(!rt.tools[0].fb_contact && v3_norm(rt.tools[0].force) == 0);
  CHECK(fabs(m->surf_x[3 * vi + 2] - vz) < 1e-5);
  runtime_destroy(&rt);
}

/* The coarse tissue sheet (triangles ~1.7 x 1 cm) in z = 0, a tool tilted
 * 150 degrees from +z (handle below, 30 degrees off the downward vertical)
 * with its tip 10 mm above the sheet: the shaft enters the sheet through the
 * middle of the centre triangle, every vertex over 6 mm from its axis (the
 * shaft's radius is 1.35 mm), so only the segment-triangle test sees it. */
static void test_shaft_coarse(void) {
  CHECK(load("scene: t\norgans:\n  - {name: block, mesh: ../meshes/tissue_block.obj, model: mass_spring_surface, "
             "material: {mass: 0.1, stiffness: 30, damping: 0.02, home_stiffness: 30, home_damping: 0.005}}\n"
             "tools:\n  - {name: a, radius: 0.003, length: 0.1, stiffness: 400}\n"));
  const model_t *m = rt.organs[0].model;
  size_t ti = 0;
  double best = INFINITY, c[3] = {0, 0, 0};
  for (size_t i = 0; i < m->nsurf_tris; i++) {
    double g[3] = {0, 0, 0};
    for (int j = 0; j < 3; j++) v3_axpy(g, m->surf_rest + 3 * m->surf_tris[3 * i + j], 1.0 / 3);
    if (v3_norm(g) < best) best = v3_norm(g), ti = i, v3_copy(c, g);
  }
  const uint32_t *tv = m->surf_tris + 3 * ti;
  const double q[4] = {cos(75 * M_PI / 180), 0, sin(75 * M_PI / 180), 0};
  runtime_set_orientation(&rt, 0, q);
  const double *ax = rt.tools[0].axis;
  CHECK(ax[2] < -0.8);
  double tip[3];
  v3_copy(tip, c);
  v3_axpy(tip, ax, -0.012);
  double z0 = 0;
  for (int j = 0; j < 3; j++) z0 += m->surf_x[3 * tv[j] + 2] / 3;
  drive(0, tip, tip, 200);
  double z1 = 0;
  for (int j = 0; j < 3; j++) z1 += m->surf_x[3 * tv[j] + 2] / 3;
  printf("shaft coarse: through triangle %zu's middle, its corners sink %.3f mm on average, the tool is pushed "
         "(%.3f %.3f %.3f) N\n",
         ti, (z0 - z1) * 1e3, rt.tools[0].force[0], rt.tools[0].force[1], rt.tools[0].force[2]);
  CHECK(z1 < z0 - 0.0001);
  CHECK(!rt.tools[0].proxy.in_contact); /* the tip itself touches nothing */
  CHECK(rt.tools[0].fb_contact && rt.tools[0].fb_organ == 0 && rt.tools[0].force[2] > 0.01);
  CHECK(fabs(v3_dot(rt.tools[0].force, ax)) < 1e-9 * v3_norm(rt.tools[0].force) + 1e-12); /* off the axis */
  runtime_destroy(&rt);
}

int main(void) {
  if (!getenv("VISCERA_SOURCE_DIR")) {
    fprintf(stderr, "test_tool_actions: VISCERA_SOURCE_DIR not set (run through ctest)\n");
    return 77;
  }
  test_grasp_unit();
  test_winding();
  test_grasp_pull_release(0);
  test_grasp_pull_release(1);
  test_stone(1);
  test_stone(0);
  test_tool_tool();
  test_shaft();
  test_shaft_coarse();
  return check_report("test_tool_actions");
}
