/* Surface mass-spring: forces against finite differences of the energy,
 * momentum conservation of internal forces, the stability bound, rollback
 * on NaN, degenerate springs, fixed vertices, shape recovery. */
#include <string.h>

#include "check.h"
#include "physics/mass_spring.h"
#include "vmath.h"

static void octahedron(mesh_t *m) {
  static const double P[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  static const uint32_t T[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  mesh_alloc(m, 6, 8, NULL);
  for (int i = 0; i < 6; i++)
    for (int k = 0; k < 3; k++) m->pos[3 * i + k] = 0.05 * P[i][k];
  memcpy(m->tris, T, sizeof T);
}

int main(void) {
  mesh_t m;
  octahedron(&m);
  ms_params_t p = {.mass = 0.06, .stiffness = 50, .damping = 0, .home_stiffness = 7, .home_damping = 0};
  mass_spring_t ms;
  verr_t err;
  CHECK(mass_spring_create(&ms, &m, &p, &err) == 0);
  CHECK(ms.nsprings == 12);
  CHECK_NEAR(ms.mass[0] * 6, 0.06, 1e-12);

  /* Perturb, then compare forces with -dE/dx by central differences. */
  unsigned s = 3;
  for (size_t i = 0; i < 3 * ms.n; i++) {
    s = s * 1664525u + 1013904223u;
    ms.x[i] += 0.01 * ((double)(s >> 16) / 65535.0 - 0.5);
  }
  double f[18];
  mass_spring_forces(&ms, ms.x, ms.v, f);
  double worst = 0;
  for (size_t c = 0; c < 3 * ms.n; c++) {
    double h = 1e-7, x0 = ms.x[c];
    ms.x[c] = x0 + h;
    double ep = mass_spring_energy(&ms);
    ms.x[c] = x0 - h;
    double em = mass_spring_energy(&ms);
    ms.x[c] = x0;
    double fd = -(ep - em) / (2 * h);
    worst = fmax(worst, fabs(fd - f[c]));
  }
  CHECK(worst < 1e-5);

  /* Internal (edge) forces alone conserve linear and angular momentum. */
  ms.p.home_stiffness = 0;
  ms.p.damping = 3;
  for (size_t i = 0; i < 3 * ms.n; i++) ms.v[i] = 0.1 * ((double)(i % 5) - 2);
  mass_spring_forces(&ms, ms.x, ms.v, f);
  double lin[3] = {0, 0, 0}, ang[3] = {0, 0, 0};
  for (size_t i = 0; i < ms.n; i++) {
    double r[3];
    v3_cross(r, ms.x + 3 * i, f + 3 * i);
    v3_add(ang, ang, r);
    v3_add(lin, lin, f + 3 * i);
  }
  CHECK(v3_norm(lin) < 1e-12);
  CHECK(v3_norm(ang) < 1e-12);
  mass_spring_destroy(&ms);

  /* Home springs only: omega = sqrt(k/m) exactly, so the bound is 2/omega. */
  ms_params_t ph = {.mass = 0.06, .stiffness = 0, .damping = 0, .home_stiffness = 10, .home_damping = 0};
  CHECK(mass_spring_create(&ms, &m, &ph, &err) == 0);
  double bound = mass_spring_stable_dt(&ms), omega = sqrt(10 / 0.01);
  /* NUMERICS.md case 1: the symplectic bound within 0.85-1.0 x 2/omega_max. */
  CHECK(bound <= 2 / omega && bound >= 0.85 * 2 / omega);
  ms.x[0] += 0.01;
  double amp = 0;
  for (int i = 0; i < 20000; i++) {
    mass_spring_step(&ms, 0.98 * bound, 1, NULL, NULL);
    amp = fmax(amp, fabs(ms.x[0] - ms.x_rest[0]));
  }
  CHECK(amp < 0.2); /* bounded: symplectic Euler below 2/omega */
  /* Above the bound the state grows until it overflows; the step that goes
   * non-finite is rolled back and the state stays finite. */
  int rolled = 0;
  for (int i = 0; i < 200000 && !rolled; i++) rolled = mass_spring_step(&ms, 1.2 * bound, 1, NULL, NULL) < 0;
  CHECK(rolled);
  int finite = 1;
  for (size_t i = 0; i < 3 * ms.n; i++) finite = finite && isfinite(ms.x[i]) && isfinite(ms.v[i]);
  CHECK(finite);
  mass_spring_destroy(&ms);

  /* NaN injected into one vertex: detected in the same step, rolled back. */
  CHECK(mass_spring_create(&ms, &m, &p, &err) == 0);
  ms.v[4] = NAN;
  double before = ms.x[0];
  CHECK(mass_spring_step(&ms, 1e-3, 1, NULL, NULL) == -1);
  CHECK(ms.x[0] == before);
  ms.v[4] = 0;
  CHECK(mass_spring_step(&ms, 1e-3, 1, NULL, NULL) == 0);

  /* Two vertices moved onto each other: forces stay finite. */
  v3_copy(ms.x + 3, ms.x);
  mass_spring_forces(&ms, ms.x, ms.v, f);
  finite = 1;
  for (int i = 0; i < 18; i++) finite = finite && isfinite(f[i]);
  CHECK(finite);
  mass_spring_destroy(&ms);

  /* Fixed vertices stay; a displaced, damped organ returns to rest. */
  ms_params_t pd = {.mass = 0.06, .stiffness = 50, .damping = 0.05, .home_stiffness = 7, .home_damping = 0.05};
  CHECK(mass_spring_create(&ms, &m, &pd, &err) == 0);
  CHECK(mass_spring_fix_below(&ms, -0.04) == 1); /* vertex 5 at z = -0.05 */
  for (size_t i = 0; i < 5; i++) ms.x[3 * i + 2] += 0.02;
  double dt = 0.9 * mass_spring_stable_dt(&ms);
  for (int i = 0; i < (int)(3.0 / dt); i++) mass_spring_step(&ms, dt, 1, NULL, NULL);
  CHECK(ms.x[3 * 5 + 2] == ms.x_rest[3 * 5 + 2]);
  double err_rest = 0;
  for (size_t i = 0; i < 3 * ms.n; i++) err_rest = fmax(err_rest, fabs(ms.x[i] - ms.x_rest[i]));
  CHECK(err_rest < 1e-4);
  mass_spring_destroy(&ms);

  /* Refused parameters. */
  ms_params_t bad = p;
  bad.mass = 0;
  CHECK(mass_spring_create(&ms, &m, &bad, &err) == -1);
  mesh_free(&m);
  return check_report("test_mass_spring");
}
