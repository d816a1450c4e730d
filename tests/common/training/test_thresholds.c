/* SPDX-License-Identifier: Apache-2.0 */
/* test_thresholds: the palpation threshold tracker reports each crossing
 * once, upward above the level and downward only below level minus the
 * hysteresis; accounts time above, contact time, mean contact force, peak
 * and path length; ignores unset levels. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "training/thresholds.h"

static const double DT = 0.001;

/* Feeds `force` for `steps` steps in contact at a fixed point; returns the
 * number of events and appends them to ev_out (up to cap). */
static int feed(thr_tracker_t *t, double force, int steps, int contact, thr_event_t *ev_out, int cap, int *nout) {
  int total = 0;
  static const double p[3] = {0, 0, 0};
  for (int i = 0; i < steps; i++) {
    thr_event_t ev[THR_COUNT];
    int n = thr_update(t, DT, force, contact, p, ev);
    for (int k = 0; k < n; k++)
      if (*nout < cap) ev_out[(*nout)++] = ev[k];
    total += n;
  }
  return total;
}

static void test_crossing_and_hysteresis(void) {
  thr_tracker_t t;
  thr_init(&t, 0.6, 0.9, 1.5);
  thr_event_t ev[16];
  int n = 0;
  CHECK(feed(&t, 0.5, 100, 1, ev, 16, &n) == 0);
  CHECK(feed(&t, 0.6, 10, 1, ev, 16, &n) == 0); /* at the level: not above */
  CHECK(feed(&t, 0.61, 100, 1, ev, 16, &n) == 1);
  CHECK(n == 1 && ev[0].which == THR_ST && ev[0].up == 1 && ev[0].level == 0.6);
  /* Inside the band (0.6 - max(0.03, 0.01) = 0.57): no chatter. */
  CHECK(feed(&t, 0.58, 50, 1, ev, 16, &n) == 0);
  CHECK(feed(&t, 0.62, 50, 1, ev, 16, &n) == 0);
  CHECK(feed(&t, 0.571, 50, 1, ev, 16, &n) == 0);
  CHECK(t.crossings[THR_ST] == 1 && t.above[THR_ST]);
  /* Below the band: one downward event. */
  CHECK(feed(&t, 0.56, 10, 1, ev, 16, &n) == 1);
  CHECK(n == 2 && ev[1].which == THR_ST && ev[1].up == 0);
  /* Time above: 100 + 50 + 50 + 50 steps in the "above" state. */
  CHECK_NEAR(t.time_above[THR_ST], 250 * DT, 1e-9);
  CHECK_NEAR(t.time_above[THR_MPF], 0, 0);
  /* A jump across every level: three up events, low to high, then three
   * down events high to low. */
  n = 0;
  CHECK(feed(&t, 2.0, 20, 1, ev, 16, &n) == 3);
  CHECK(ev[0].which == THR_ST && ev[1].which == THR_MPF && ev[2].which == THR_SFT);
  CHECK(ev[0].up && ev[1].up && ev[2].up);
  CHECK(feed(&t, 0.0, 20, 0, ev, 16, &n) == 3);
  CHECK(ev[3].which == THR_SFT && ev[4].which == THR_MPF && ev[5].which == THR_ST);
  CHECK(!ev[3].up && !ev[4].up && !ev[5].up);
  CHECK_NEAR(t.time_above[THR_SFT], 20 * DT, 1e-9);
  CHECK_NEAR(t.time_above[THR_MPF], 20 * DT, 1e-9);
  CHECK_NEAR(t.time_above[THR_ST], 270 * DT, 1e-9);
  CHECK(t.crossings[THR_ST] == 2 && t.crossings[THR_MPF] == 1 && t.crossings[THR_SFT] == 1);
  CHECK_NEAR(t.peak_force, 2.0, 0);
  /* Hysteresis floor: a small level uses the 0.01 N minimum band. */
  thr_init(&t, 0.1, 0, 0);
  n = 0;
  CHECK(feed(&t, 0.2, 1, 1, ev, 16, &n) == 1);
  CHECK(feed(&t, 0.0905, 1, 1, ev, 16, &n) == 0); /* 0.1 - 0.01 = 0.09 */
  CHECK(feed(&t, 0.089, 1, 1, ev, 16, &n) == 1);
}

static void test_unset_and_contact(void) {
  thr_tracker_t t;
  thr_init(&t, 0, 0, 0);
  thr_event_t ev[4];
  int n = 0;
  CHECK(feed(&t, 50, 100, 1, ev, 4, &n) == 0);
  for (int k = 0; k < THR_COUNT; k++) CHECK(t.time_above[k] == 0 && t.crossings[k] == 0);
  /* Mean contact force counts only contact steps: 100 steps at 50 N in
   * contact, 100 at 0 N out of contact, 100 at 10 N in contact. */
  CHECK(feed(&t, 0, 100, 0, ev, 4, &n) == 0);
  CHECK(feed(&t, 10, 100, 1, ev, 4, &n) == 0);
  CHECK_NEAR(t.contact_time, 0.2, 1e-9);
  CHECK_NEAR(thr_mean_contact_force(&t), 30, 1e-9);
  CHECK_NEAR(t.peak_force, 50, 0);
  /* Non-finite or negative force counts as 0. */
  CHECK(feed(&t, NAN, 1, 1, ev, 4, &n) == 0 && t.peak_force == 50);
  thr_init(&t, 1, 0, 0);
  CHECK(thr_mean_contact_force(&t) == 0);
  CHECK(strcmp(thr_name(THR_MPF), "MPF") == 0 && strcmp(thr_name(THR_SFT), "SFT") == 0);
}

static void test_path_length(void) {
  thr_tracker_t t;
  thr_init(&t, 1, 0, 0);
  thr_event_t ev[THR_COUNT];
  /* A 3-4-5 step then back: 5 + 5 cm. */
  const double a[3] = {0, 0, 0}, b[3] = {0.03, 0.04, 0};
  thr_update(&t, DT, 0, 0, a, ev);
  CHECK_NEAR(t.path_length, 0, 0);
  thr_update(&t, DT, 0, 0, b, ev);
  CHECK_NEAR(t.path_length, 0.05, 1e-12);
  thr_update(&t, DT, 0, 0, a, ev);
  CHECK_NEAR(t.path_length, 0.10, 1e-12);
  /* Not driven (NULL): the path restarts, no jump counted. */
  thr_update(&t, DT, 0, 0, NULL, ev);
  const double far[3] = {1, 1, 1};
  thr_update(&t, DT, 0, 0, far, ev);
  CHECK_NEAR(t.path_length, 0.10, 1e-12);
  /* A straight line in 1000 small steps sums to its length. */
  thr_init(&t, 0, 0, 0);
  for (int i = 0; i <= 1000; i++) {
    double p[3] = {0, 0, 0.07 - 0.043 * i / 1000.0};
    thr_update(&t, DT, 0, 0, p, ev);
  }
  CHECK_NEAR(t.path_length, 0.043, 1e-12);
}

int main(void) {
  test_crossing_and_hysteresis();
  test_unset_and_contact();
  test_path_length();
  return check_report("test_thresholds");
}
