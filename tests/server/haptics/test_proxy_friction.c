/* SPDX-License-Identifier: Apache-2.0 */
/* test_proxy_friction: friction and force shading on the god-object proxy
 * (server/haptics/proxy.c, docs/methods.md A eq. 12).
 * - Friction: on a plane, the proxy sticks while the tangential spring
 *   force is within mu times the normal force, then slides keeping the
 *   ratio at mu; mu = 0 slides freely (proxy_update).
 * - Force shading: on a roof of two facets, the contact normal turns
 *   continuously across the ridge with vertex normals, and jumps by the
 *   facet angle without them. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "haptics/proxy.h"
#include "vmath.h"

static const double plane_x[] = {-0.1, -0.1, 0, 0.1, -0.1, 0, 0.1, 0.1, 0, -0.1, 0.1, 0};
static const uint32_t plane_t[] = {0, 1, 2, 0, 2, 3};

static void press(proxy_t *p, const proxy_surface_t *s, double mu, double x, double f[3]) {
  double above[3] = {0, 0, 0.01}, in[3] = {0, 0, -0.005}, slid[3] = {x, 0, -0.005};
  proxy_reset(p);
  proxy_update_friction(p, above, s, 1, 400, 100, mu, f);
  proxy_update_friction(p, in, s, 1, 400, 100, mu, f);
  CHECK(p->in_contact);
  CHECK_NEAR(p->pos[0], 0, 1e-12);
  proxy_update_friction(p, slid, s, 1, 400, 100, mu, f);
}

static void test_friction(void) {
  proxy_surface_t s = {.x = plane_x, .tris = plane_t, .ntris = 2};
  proxy_t p;
  double f[3];
  /* mu 0.5, 5 mm deep: the cone allows 2.5 mm of tangential offset. */
  press(&p, &s, 0.5, 0.002, f);
  CHECK_NEAR(p.pos[0], 0, 1e-12);       /* sticks */
  CHECK_NEAR(f[0], -400 * 0.002, 1e-9); /* the hand feels the tangential pull */
  CHECK_NEAR(f[2], 400 * 0.005, 1e-9);
  press(&p, &s, 0.5, 0.004, f);
  CHECK_NEAR(p.pos[0], 0.004 - 0.0025, 1e-12); /* slides, stays on the cone */
  CHECK_NEAR(fabs(f[0]) / f[2], 0.5, 1e-9);
  /* A further slide keeps dragging behind by the cone. */
  double more[3] = {0.01, 0, -0.005};
  proxy_update_friction(&p, more, &s, 1, 400, 100, 0.5, f);
  CHECK_NEAR(p.pos[0], 0.01 - 0.0025, 1e-12);
  /* Frictionless: the proxy sits right above the device. */
  press(&p, &s, 0, 0.004, f);
  CHECK_NEAR(p.pos[0], 0.004, 1e-12);
  CHECK_NEAR(f[0], 0, 1e-9);
  /* Touching without depth: no normal force, no friction hold. */
  double zero_depth[3] = {0.003, 0, 0};
  press(&p, &s, 0.5, 0, f);
  proxy_update_friction(&p, zero_depth, &s, 1, 400, 100, 0.5, f);
  CHECK_NEAR(p.pos[0], 0.003, 1e-12);
}

/* A roof: ridge along y at x = 0, z = 0.01 (vertices 1 and 4); facets
 * slope down to x = -0.05 (0, 3) and x = +0.05 (2, 5), 11.3 deg each. */
static const double roof_x[] = {-0.05, -0.05, 0, 0, -0.05, 0.01, 0.05, -0.05, 0,
                                -0.05, 0.05,  0, 0, 0.05,  0.01, 0.05, 0.05,  0};
static const uint32_t roof_t[] = {0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4};

static void normal_at(const proxy_surface_t *s, double x, double n[3]) {
  proxy_t p;
  double f[3], above[3] = {x, 0, 0.05}, in[3] = {x, 0, 0.0};
  proxy_reset(&p);
  proxy_update(&p, above, s, 1, 400, 100, f);
  proxy_update(&p, in, s, 1, 400, 100, f);
  CHECK(p.in_contact);
  v3_copy(n, p.normal);
}

static void test_force_shading(void) {
  double vn[18];
  proxy_vertex_normals(6, roof_x, 4, roof_t, vn);
  /* Halfway along the ridge its two vertex normals average straight up. */
  CHECK_NEAR(vn[3 * 1 + 0] + vn[3 * 4 + 0], 0, 1e-12);
  CHECK(vn[3 * 0 + 0] < 0 && vn[3 * 2 + 0] > 0);
  proxy_surface_t flat = {.x = roof_x, .tris = roof_t, .ntris = 4};
  proxy_surface_t shaded = flat;
  shaded.vn = vn;
  shaded.nvn = 6;
  double a[3], b[3];
  /* Just left and right of the ridge. */
  normal_at(&flat, -1e-4, a);
  normal_at(&flat, 1e-4, b);
  double jump_flat = acos(fmin(1, v3_dot(a, b)));
  normal_at(&shaded, -1e-4, a);
  normal_at(&shaded, 1e-4, b);
  double jump_shaded = acos(fmin(1, v3_dot(a, b)));
  printf("force shading: normal turns %.2f deg across the ridge with vertex normals, %.2f deg without\n",
         jump_shaded * 180 / M_PI, jump_flat * 180 / M_PI);
  CHECK(jump_flat > 20 * M_PI / 180); /* two facets of +-11.3 deg */
  CHECK(jump_shaded < 0.1 * M_PI / 180);
  /* Mid-facet the shaded normal lies between the ridge's and the facet's. */
  normal_at(&shaded, -0.03, a);
  CHECK(a[0] < 0 && a[2] > 0.98);
  /* A vn array too short for the triangles is ignored (face normals). */
  shaded.nvn = 2;
  normal_at(&shaded, -1e-4, a);
  normal_at(&flat, -1e-4, b);
  CHECK_NEAR(v3_dot(a, b), 1, 1e-12);
}

int main(void) {
  test_friction();
  test_force_shading();
  return check_report("test_proxy_friction");
}
