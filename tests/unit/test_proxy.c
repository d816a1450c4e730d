/* God-object proxy on a flat square patch (z = 0, normal +z) and on a closed
 * octahedron: force f = K (proxy - device) (seed 000 eq. 12), proxy stays on
 * the surface however deep the device goes, clamped force, release above the
 * surface, frictionless sliding, no contact from behind. */
#include <string.h>

#include "check.h"
#include "haptics/proxy.h"
#include "vmath.h"

int main(void) {
  double x[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  uint32_t tris[] = {0, 1, 2, 0, 2, 3};
  proxy_surface_t s = {x, tris, 2, 0, NULL};
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
  return check_report("test_proxy");
}
