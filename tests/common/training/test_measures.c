/* SPDX-License-Identifier: Apache-2.0 */
/* Report measures on synthetic sample arrays: a ramp up, hold and ramp down
 * whose threshold times are known in closed form, with and without the
 * hysteresis of common/training/thresholds.c, gaps in the samples, force chatter at
 * a level, path length with gaps and non-finite positions, first motion,
 * and pairing of task events. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "training/measures.h"

#define DT 1e-3

/* f(t): 0 -> 1 N over [0, 1] s, holds 1 N to 2 s, back to 0 at 3 s, then 0
 * to 3.5 s; in contact on [0.2, 2.8] s. Samples at (i+1) DT. */
static size_t ramp(rep_force_sample_t *s, double skip_lo, double skip_hi) {
  size_t n = 0;
  for (int i = 0; i < 3500; i++) {
    double t = (i + 1) * DT;
    if (t > skip_lo && t < skip_hi) continue;
    double f = t < 1 ? t : t < 2 ? 1 : t < 3 ? 3 - t : 0;
    s[n++] = (rep_force_sample_t){t, f, t >= 0.2 - 1e-9 && t < 2.8 - 1e-9};
  }
  return n;
}

static void test_ramp(void) {
  static rep_force_sample_t s[4000];
  size_t n = ramp(s, INFINITY, INFINITY);
  const double lv[THR_COUNT] = {0.5, 0.8, 1.5};
  rep_force_measures_t m;
  rep_force_measures(s, n, lv, DT, 0.5, &m);
  /* Up when f > L; down only when f < L - max(5 % L, 0.01 N): ST leaves at
   * f < 0.475 (t = 2.525), MPF at f < 0.76 (t = 2.24). Without hysteresis
   * these would be 2.000 s and 1.400 s. */
  CHECK_NEAR(m.time_above[THR_ST], 2.525 - 0.5, 2.5e-3);
  CHECK_NEAR(m.time_above[THR_MPF], 2.24 - 0.8, 2.5e-3);
  CHECK(m.time_above[THR_SFT] == 0);
  CHECK(m.crossings[THR_ST] == 1 && m.crossings[THR_MPF] == 1 && m.crossings[THR_SFT] == 0);
  CHECK_NEAR(m.peak_force, 1.0, 1e-12);
  CHECK_NEAR(m.contact_time, 2.6, 1.5e-3);
  /* mean of f over [0.2, 2.8]: (integral 0.2..1 of t + 1 + integral 2..2.8 of (3-t)) / 2.6 */
  double integral = (1 - 0.04) / 2 + 1 + (0.8 * 3 - (2.8 * 2.8 - 4) / 2);
  CHECK_NEAR(m.mean_contact_force, integral / 2.6, 2e-3);
  CHECK_NEAR(m.first_contact_t, 0.2, 1.5e-3);
  CHECK_NEAR(m.last_contact_end_t, 2.8, 1.5e-3);
  CHECK_NEAR(m.first_t, DT, 1e-12);
  CHECK_NEAR(m.last_t, 3.5, 1e-9);
  CHECK(m.samples == n);

  /* Unset thresholds never count. */
  const double none[THR_COUNT] = {0, 0, 0};
  rep_force_measures(s, n, none, DT, 0.5, &m);
  CHECK(m.time_above[THR_ST] == 0 && m.crossings[THR_ST] == 0);
}

/* Holes in the samples. */
static void test_gap(void) {
  static rep_force_sample_t s[4000];
  const double lv[THR_COUNT] = {0.5, 0.8, 1.5};
  rep_force_measures_t m;
  /* A hole shorter than the gap limit is credited to the sample after it
   * (the lost steps are assumed to be like it): a 0.3 s hole costs nothing. */
  size_t n = ramp(s, 1.2, 1.5);
  rep_force_measures(s, n, lv, DT, 0.5, &m);
  CHECK_NEAR(m.time_above[THR_ST], 2.025, 3.5e-3);
  CHECK_NEAR(m.contact_time, 2.6, 1.5e-3);
  /* 0.6 s in mid-contact, longer than the gap limit: still lost samples
   * (a released tool leaves the contact first), credited. */
  n = ramp(s, 1.2, 1.8);
  rep_force_measures(s, n, lv, DT, 0.5, &m);
  CHECK_NEAR(m.time_above[THR_ST], 2.025, 3.5e-3);
  CHECK_NEAR(m.time_above[THR_MPF], 1.44, 3.5e-3);
  CHECK_NEAR(m.contact_time, 2.6, 1.5e-3);
  /* 0.6 s from inside the contact to outside it (a release): not credited,
   * the contact time loses the 0.1 s of contact in the hole. */
  n = ramp(s, 2.7, 3.3);
  rep_force_measures(s, n, lv, DT, 0.5, &m);
  CHECK_NEAR(m.contact_time, 2.5, 1.5e-3);
  CHECK_NEAR(m.time_above[THR_ST], 2.025, 3.5e-3);
}

/* Force hovering around MPF: one crossing, not one per wiggle. */
static void test_chatter(void) {
  rep_force_sample_t s[2000];
  for (int i = 0; i < 2000; i++) s[i] = (rep_force_sample_t){(i + 1) * DT, (i % 2) ? 0.81 : 0.79, 1};
  const double lv[THR_COUNT] = {0.5, 0.8, 1.5};
  rep_force_measures_t m;
  rep_force_measures(s, 2000, lv, DT, 0.5, &m);
  CHECK(m.crossings[THR_MPF] == 1);
  CHECK_NEAR(m.time_above[THR_MPF], 1.999, 1e-9);
  /* Non-finite or negative forces count as zero (the tracker's rule). */
  s[5].force = NAN;
  s[6].force = -3;
  rep_force_measures(s, 10, lv, DT, 0.5, &m);
  CHECK(isfinite(m.peak_force) && m.peak_force == 0.81);
}

static void test_path(void) {
  /* A 1 cm square traced in 4000 samples, 1 ms apart: 4 cm. */
  static rep_pos_sample_t p[4100];
  size_t n = 0;
  const double corner[5][2] = {{0, 0}, {0.01, 0}, {0.01, 0.01}, {0, 0.01}, {0, 0}};
  for (int side = 0; side < 4; side++)
    for (int k = 0; k < 1000; k++) {
      double a = k / 1000.0;
      p[n] = (rep_pos_sample_t){n * DT,
                                {corner[side][0] + a * (corner[side + 1][0] - corner[side][0]),
                                 corner[side][1] + a * (corner[side + 1][1] - corner[side][1]), 0.05},
                                n + 1};
      n++;
    }
  p[n] = (rep_pos_sample_t){n * DT, {0, 0, 0.05}, n + 1};
  n++;
  CHECK_NEAR(rep_path_length(p, n, 0.5), 0.04, 1e-12);
  /* After a 1 s silence of the client (next seq) the tool reappears 5 cm
   * away: the jump is a pause, not travel. */
  p[n] = (rep_pos_sample_t){n * DT + 1.0, {0, 0, 0.10}, n + 1};
  n++;
  CHECK_NEAR(rep_path_length(p, n, 0.5), 0.04, 1e-12);
  /* The same second, but the client sent 1000 commands the recording lost:
   * the tool travelled, at least the straight 5 cm. */
  p[n - 1].seq += 1000;
  CHECK_NEAR(rep_path_length(p, n, 0.5), 0.09, 1e-12);
  p[n - 1].seq -= 1000;
  /* A non-finite position breaks the path instead of poisoning it. */
  p[2000].p[0] = NAN;
  double len = rep_path_length(p, n, 0.5);
  CHECK(isfinite(len) && len < 0.04 && len > 0.0399);
  /* First motion: the tool starts moving at once here; a tool that waits
   * 0.3 s first reports 0.3 s. */
  rep_pos_sample_t w[600];
  for (int i = 0; i < 600; i++) w[i] = (rep_pos_sample_t){i * DT, {0, 0, i < 300 ? 0.07 : 0.07 - (i - 300) * 1e-5}, 0};
  CHECK_NEAR(rep_first_motion(w, 600, 1e-4), 0.3105, 1.01e-3); /* 1e-4 reached at 10 or 11 steps */
  for (int i = 0; i < 600; i++) w[i].p[2] = 0.07;
  CHECK(isnan(rep_first_motion(w, 600, 1e-4)));
}

static void test_tasks(void) {
  rep_task_event_t ev[] = {
      {1.0, REP_TASK_STARTED, -1, "palpate", NAN},   {1.5, REP_TASK_STARTED, -1, "stone", NAN},
      {3.0, REP_TASK_COMPLETED, -1, "palpate", NAN}, {4.0, REP_TASK_COMPLETED, -1, "grasp", NAN},
      {6.5, REP_TASK_COMPLETED, -1, "stone", NAN},   {7.0, REP_TASK_STARTED, -1, "palpate", NAN},
  };
  rep_task_t t[8];
  size_t n = rep_tasks(ev, sizeof ev / sizeof ev[0], 0.25, t, 8);
  CHECK(n == 4);
  CHECK(strcmp(t[0].name, "palpate") == 0 && t[0].start == 1.0 && t[0].end == 3.0 && t[0].started_seen);
  CHECK(strcmp(t[1].name, "stone") == 0 && t[1].start == 1.5 && t[1].end == 6.5);
  /* completed without a start: from the session start */
  CHECK(strcmp(t[2].name, "grasp") == 0 && t[2].start == 0.25 && t[2].end == 4.0 && !t[2].started_seen);
  /* started again, never completed */
  CHECK(strcmp(t[3].name, "palpate") == 0 && t[3].start == 7.0 && isnan(t[3].end));
  /* the output is bounded */
  CHECK(rep_tasks(ev, sizeof ev / sizeof ev[0], 0.25, t, 2) == 2);
}

/* Two tasks overlapping in time, named alike: the ids pair them (the old
 * pairing by the text's first word gave 0.79 s and 2.46 s for a session
 * whose server said 1.296 s and 2.539 s). */
static void test_tasks_by_id(void) {
  rep_task_event_t ev[] = {
      {0.500, REP_TASK_STARTED, 0, "task", NAN},
      {0.520, REP_TASK_STARTED, 1, "task", NAN},
      {1.796, REP_TASK_COMPLETED, 0, "task", NAN},
      {3.060, REP_TASK_COMPLETED, 1, "task", 2.539},
  };
  rep_task_t t[4];
  CHECK(rep_tasks(ev, 4, 0, t, 4) == 2);
  CHECK(t[0].id == 0 && fabs(t[0].end - t[0].start - 1.296) < 1e-9);
  /* the server's own operation time, when the completion carries it */
  CHECK(t[1].id == 1 && fabs(t[1].end - t[1].start - 2.539) < 1e-9 && fabs(t[1].start - 0.521) < 1e-9);
}

/* The server answers a command before the tissue step (stamped with the
 * step's start) right after the previous step's own answer (stamped with
 * its end): two samples of one instant take no time. 1 s in contact with
 * every tenth step answered twice is still 1 s. */
static void test_same_instant(void) {
  static rep_force_sample_t s[1200];
  size_t n = 0;
  for (int k = 1; k <= 1000; k++) {
    s[n++] = (rep_force_sample_t){k * DT, 1.0, 1};
    if (k % 10 == 0) s[n++] = (rep_force_sample_t){k * DT, 1.0, 1};
  }
  const double lv[THR_COUNT] = {0.5, 0.8, 1.5};
  rep_force_measures_t m;
  rep_force_measures(s, n, lv, DT, 0.5, &m);
  CHECK(n == 1100);
  CHECK_NEAR(m.contact_time, 1.0, 1.5e-9);
  CHECK_NEAR(m.time_above[THR_MPF], 1.0, 1.5e-9);
}

int main(void) {
  test_ramp();
  test_gap();
  test_same_instant();
  test_chatter();
  test_path();
  test_tasks();
  test_tasks_by_id();
  return check_report("test_measures");
}
