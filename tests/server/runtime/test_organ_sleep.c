/* SPDX-License-Identifier: Apache-2.0 */
/* test_organ_sleep: organs at rest are not stepped (server/runtime/organ_sleep.h).
 * - the stillness evidence: `need` still steps put an organ to sleep; a
 *   vertex moving more than the limit, a NaN, a disturbance or a new
 *   topology restart the count; waking counts only a sleeping organ;
 * - the reach test (box around a swollen segment), NaN = near;
 * - scene keys physics.sleep_speed / sleep_after / publish_keepalive:
 *   defaults, ranges, the 2-step minimum refused with the line;
 * - on the real runtime (kidney, mass-spring, probe), two scenes that
 *   differ only in sleeping, driven by the same probe path: the sleeping
 *   one skips most steps while the probe is away, wakes before the probe
 *   touches, and the force on the probe at every step equals the
 *   never-sleeping one (1e-9 N) through a press; after the probe leaves it
 *   sleeps again, and the surfaces differ by less than the mesh
 *   quantisation (1e-5 m); a shaft reaching the organ with its tip far
 *   keeps it awake;
 * - organ_sleep_observe_listed, told which vertices changed (with others
 *   and an index past the end among them), decides and records exactly as
 *   the full observation over 400 random steps (still, moving, disturbed,
 *   falling asleep and woken); a list missing a mover calls it still. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_rng.h"
#include "test_runtime.h"
#include "runtime/organ_sleep.h"
#include "runtime/scene_runtime.h"

static runtime_t rt_on, rt_off; /* large */
static scene_t sc_on, sc_off, sc;
static verr_t e;

static void test_evidence(void) {
  organ_sleep_t s;
  CHECK(organ_sleep_init(&s, 2, &e) == 0);
  double x[6] = {0, 0, 0, 1, 1, 1};
  const double lim = 1e-6;
  CHECK(organ_sleep_observe(&s, x, 2, lim, 3, 0) == 0); /* first: no previous surface */
  CHECK(s.still == 0);
  CHECK(organ_sleep_observe(&s, x, 2, lim, 3, 0) == 0);
  CHECK(organ_sleep_observe(&s, x, 2, lim, 3, 0) == 0);
  CHECK(s.still == 2 && !s.asleep);
  x[4] += 0.9e-6; /* within the limit: still */
  CHECK(organ_sleep_observe(&s, x, 2, lim, 3, 0) == 1);
  CHECK(s.asleep && s.sleeps == 1);
  organ_sleep_wake(&s);
  CHECK(!s.asleep && s.wakes == 1 && s.still == 0);
  organ_sleep_wake(&s); /* awake already: not a wake */
  CHECK(s.wakes == 1);
  /* A vertex moving 1.1 x the limit restarts the count. */
  CHECK(organ_sleep_observe(&s, x, 2, lim, 3, 0) == 0);
  CHECK(organ_sleep_observe(&s, x, 2, lim, 3, 0) == 0);
  CHECK(s.still == 2);
  x[3] += 1.1e-6;
  CHECK(organ_sleep_observe(&s, x, 2, lim, 3, 0) == 0);
  CHECK(s.still == 0);
  /* A disturbance restarts it although nothing moved. */
  CHECK(organ_sleep_observe(&s, x, 2, lim, 3, 0) == 0);
  CHECK(organ_sleep_observe(&s, x, 2, lim, 3, 1) == 0);
  CHECK(s.still == 0);
  /* NaN is motion. */
  CHECK(organ_sleep_observe(&s, x, 2, lim, 3, 0) == 0);
  double xn[6];
  memcpy(xn, x, sizeof xn);
  xn[0] = NAN;
  CHECK(organ_sleep_observe(&s, xn, 2, lim, 3, 0) == 0);
  CHECK(s.still == 0);
  /* A different vertex count (a cut) restarts the evidence and grows. */
  double y[9] = {0, 0, 0, 1, 1, 1, 2, 2, 2};
  CHECK(organ_sleep_observe(&s, y, 3, lim, 3, 0) == 0);
  CHECK(s.n == 3 && s.still == 0 && s.cap >= 3);
  for (int i = 0; i < 2; i++) CHECK(organ_sleep_observe(&s, y, 3, lim, 3, 0) == 0);
  CHECK(organ_sleep_observe(&s, y, 3, lim, 3, 0) == 1);
  organ_sleep_free(&s);
}

static void test_listed(void) {
  enum { N = 500 };
  static double x[3 * N];
  uint32_t list[64];
  uint64_t rng = 0x9e3779b97f4a7c15ull;
  organ_sleep_t a, b;
  CHECK(organ_sleep_init(&a, N, &e) == 0 && organ_sleep_init(&b, N, &e) == 0);
  for (size_t i = 0; i < 3 * N; i++) x[i] = test_rng_uniform(&rng);
  const double lim = 1e-4;
  CHECK(organ_sleep_observe(&a, x, N, lim, 5, 0) == 0);
  CHECK(organ_sleep_observe_listed(&b, x, N, NULL, 0, lim, 5, 0) == 0);
  size_t differ = 0, sleeps = 0;
  for (int step = 0; step < 400; step++) {
    /* Mostly still (creeps below the limit), now and then a mover. */
    size_t n = 0;
    int moving = test_rng_uniform(&rng) < 0.2;
    for (int j = 0; j < 30; j++) {
      uint32_t i = (uint32_t)(test_rng_uniform(&rng) * N);
      double amp = (moving && j == 0) ? 10 * lim : 0.5 * lim;
      for (int k = 0; k < 3; k++) x[3 * i + (uint32_t)k] += (test_rng_uniform(&rng) - 0.5) * amp;
      list[n++] = i;
    }
    for (int j = 0; j < 5; j++) list[n++] = (uint32_t)(test_rng_uniform(&rng) * N);
    list[n++] = N; /* past the end: ignored */
    int disturbed = test_rng_uniform(&rng) < 0.1;
    int ra = organ_sleep_observe(&a, x, N, lim, 5, disturbed);
    int rb = organ_sleep_observe_listed(&b, x, N, list, n, lim, 5, disturbed);
    differ += ra != rb || a.still != b.still || a.asleep != b.asleep || memcmp(a.prev, b.prev, sizeof x) != 0;
    if (ra == 1) {
      sleeps++;
      organ_sleep_wake(&a);
      organ_sleep_wake(&b);
    }
  }
  printf("listed observation: 400 steps, %zu differ from the full one, %zu sleeps\n", differ, sleeps);
  CHECK(differ == 0 && sleeps > 0);
  /* A mover left off the list goes unseen. */
  x[0] += 10 * lim;
  uint32_t other = 7;
  int still_before = (int)b.still;
  organ_sleep_observe_listed(&b, x, N, &other, 1, lim, 1000, 0);
  CHECK((int)b.still == still_before + 1);
  organ_sleep_free(&a);
  organ_sleep_free(&b);
}

static void test_reach(void) {
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const double a[3] = {2, 2, 2}, b[3] = {3, 3, 3}, c[3] = {0.5, 0.5, -5}, d[3] = {0.5, 0.5, 5};
  CHECK(organ_sleep_box_near(lo, hi, a, b, 0.5) == 0);
  CHECK(organ_sleep_box_near(lo, hi, a, b, 1.0) == 1); /* 1 away on every axis */
  CHECK(organ_sleep_box_near(lo, hi, c, d, 0) == 1);   /* passes through */
  CHECK(organ_sleep_box_near(lo, hi, c, c, 4.9) == 0);
  const double n[3] = {NAN, 5, 5};
  CHECK(organ_sleep_box_near(lo, hi, n, n, 0) == 1);
}

#define KIDNEY(physics)                                                                                                \
  "scene: t\nphysics: {" physics "}\n"                                                                                 \
  "organs:\n  - {name: kidney, mesh: ../meshes/kidney.obj, material: {mass: 0.15, stiffness: 30, damping: 0.02, "      \
  "home_stiffness: 30, home_damping: 0.005}}\n"                                                                        \
  "tools:\n  - {name: probe, radius: 0.003, stiffness: 400, max_force: 4}\n"

static int load(const char *yaml, scene_t *s, runtime_t *r) { return test_runtime_load(r, s, yaml, &e); }

static void test_keys(void) {
  CHECK(load(KIDNEY("dt: 0.001"), &sc, NULL));
  CHECK(sc.sleep_speed == 0 && fabs(sc.sleep_after - 0.1) < 1e-15);
  CHECK(load(KIDNEY("sleep_speed: 1.0e-4, sleep_after: 0.05"), &sc, NULL));
  CHECK(sc.sleep_speed == 1e-4 && sc.sleep_after == 0.05);
  CHECK(!load(KIDNEY("dt: 0.001, sleep_after: 0.0015"), &sc, NULL));
  CHECK(strstr(e.msg, "physics.sleep_after") && strstr(e.msg, "two steps") && strstr(e.msg, ":2"));
  CHECK(!load(KIDNEY("sleep_speed: -1"), &sc, NULL));
  CHECK(strstr(e.msg, "sleep_speed") != NULL);
  CHECK(!load(KIDNEY("sleep_speed: 1"), &sc, NULL));
  CHECK(!load(KIDNEY("sleep_after: 0"), &sc, NULL));
  CHECK(load(KIDNEY("publish_keepalive: 1.5"), &sc, NULL) && sc.publish_keepalive == 1.5);
  CHECK(!load(KIDNEY("publish_keepalive: -1"), &sc, NULL));
  CHECK(strstr(e.msg, "physics.publish_keepalive") != NULL);
}

/* Both runtimes one step with the probe at p; returns |f_on - f_off|. */
static double step_both(const double p[3]) {
  runtime_set_tool(&rt_on, 0, p, 4);
  runtime_set_tool(&rt_off, 0, p, 4);
  runtime_step(&rt_on);
  runtime_step(&rt_off);
  rt_on.events.n = rt_off.events.n = 0;
  double d[3];
  for (int k = 0; k < 3; k++) d[k] = rt_on.tools[0].force[k] - rt_off.tools[0].force[k];
  return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

static double max_surface_diff(void) {
  const model_t *a = rt_on.organs[0].model, *b = rt_off.organs[0].model;
  double m = 0;
  for (size_t i = 0; i < 3 * a->nsurf; i++) m = fmax(m, fabs(a->surf_x[i] - b->surf_x[i]));
  return m;
}

static void test_runtime(void) {
  if (!load(KIDNEY("sleep_speed: 1.0e-4, sleep_after: 0.05"), &sc_on, &rt_on) ||
      !load(KIDNEY("dt: 0.001"), &sc_off, &rt_off)) {
    CHECK(0);
    return;
  }
  const organ_sleep_t *zz = &rt_on.organs[0].sleep;
  const double away[3] = {0.012, 0.004, 0.07}, press[3] = {0.012, 0.004, 0.027};
  double worst = 0, peak = 0;
  /* Away: the organ at rest falls asleep after 50 still steps. */
  for (int i = 0; i < 300; i++) worst = fmax(worst, step_both(away));
  CHECK(zz->asleep && zz->sleeps == 1);
  CHECK(zz->slept_steps >= 200);
  CHECK(rt_on.organs_stepped == 0 && rt_off.organs_stepped == 1);
  uint64_t slept_away = zz->slept_steps;
  /* Down, hold, up: awake before the first contact, same force throughout. */
  int woke_before_contact = -1, touched = 0;
  for (int i = 0; i < 1500; i++) {
    double p[3], s = i < 500 ? i / 500.0 : i < 800 ? 1.0 : 1.0 - (i - 800) / 500.0;
    if (s < 0) s = 0;
    for (int k = 0; k < 3; k++) p[k] = away[k] + (press[k] - away[k]) * s;
    worst = fmax(worst, step_both(p));
    peak = fmax(peak, sqrt(rt_off.tools[0].force[0] * rt_off.tools[0].force[0] +
                           rt_off.tools[0].force[1] * rt_off.tools[0].force[1] +
                           rt_off.tools[0].force[2] * rt_off.tools[0].force[2]));
    if (!touched && rt_off.tools[0].proxy.in_contact) {
      touched = 1;
      woke_before_contact = !zz->asleep && zz->wakes == 1;
    }
  }
  CHECK(touched && woke_before_contact == 1);
  CHECK(peak > 0.5);
  CHECK(worst <= 1e-9);
  printf("  press: peak %.4f N, largest force difference sleeping vs never %.3g N\n", peak, worst);
  /* Away again: it settles and sleeps again; the frozen residual motion is
   * below what a viewer can see. */
  for (int i = 0; i < 600; i++) step_both(away);
  CHECK(zz->asleep && zz->sleeps == 2);
  CHECK(zz->slept_steps > slept_away);
  double diff = max_surface_diff();
  CHECK(diff < 1e-5);
  printf("  %llu of %llu steps skipped; surface difference after the press %.3g m\n",
         (unsigned long long)zz->slept_steps, (unsigned long long)rt_on.steps, diff);
  /* The shaft: tip 4.5 cm beside the box (beyond the reach), shaft pointing
   * into it (+z turned to -x): awake. Pointing away (+z): asleep again. */
  const double beside[3] = {0.1, 0, 0.02};
  const double into[4] = {sqrt(0.5), 0, -sqrt(0.5), 0}, up[4] = {1, 0, 0, 0};
  runtime_set_orientation(&rt_on, 0, up);
  runtime_set_orientation(&rt_off, 0, up);
  for (int i = 0; i < 200; i++) step_both(beside);
  CHECK(zz->asleep);
  runtime_set_orientation(&rt_on, 0, into);
  runtime_set_orientation(&rt_off, 0, into);
  step_both(beside);
  CHECK(!zz->asleep && rt_on.organs_stepped == 1);
  runtime_destroy(&rt_on);
  runtime_destroy(&rt_off);
}

int main(void) {
  test_evidence();
  test_listed();
  test_reach();
  test_keys();
  test_runtime();
  return check_report("test_organ_sleep");
}
