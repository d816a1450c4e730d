/* SPDX-License-Identifier: Apache-2.0 */
/* Schedule reconstruction of viscera-resim (server/resim/resim_schedule.h) on
 * synthetic command / feedback arrays: exact when nothing is missing, gaps
 * bridged or estimated and counted, releases honoured, unrecorded commands
 * replaced and counted, conflicts and garbage handled; and a property run:
 * a known schedule, 30 % of its feedback dropped at random, is rebuilt with
 * every wrong step inside a gap counted as ambiguous. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "resim/resim_schedule.h"

#define MAXS 4096

static resim_cmd_t cmds[MAXS];
static resim_fb_t fbs[MAXS];
static uint64_t rels[16];
static int32_t out[MAXS + 1];

/* Commands seq 1..n, written at 1 ms intervals from t = 1 s. */
static size_t make_cmds(size_t n) {
  for (size_t i = 0; i < n; i++) {
    memset(&cmds[i], 0, sizeof cmds[i]);
    cmds[i].seq = i + 1;
    cmds[i].wall_ns = 1000000000 + (int64_t)i * 1000000;
    cmds[i].pos[0] = (double)(i + 1);
    cmds[i].max_force = 4;
  }
  return n;
}

static resim_fb_t fb(uint64_t step, uint64_t seq) {
  /* Step k's feedback is written about 0.4 ms after command k arrived. */
  return (resim_fb_t){.step = step, .seq = seq, .wall_ns = 1000000000 + ((int64_t)step - 1) * 1000000 + 400000};
}

/* The seq scheduled at step k (0 inactive). */
static uint64_t seq_at(const resim_tool_input_t *in, uint64_t k) { return out[k] < 0 ? 0 : in->cmd[out[k]].seq; }

static int build(resim_tool_input_t *in, uint64_t nsteps, resim_schedule_stats_t *st) {
  memset(st, 0, sizeof *st);
  verr_t e;
  int rc = resim_schedule_build(in, nsteps, out, st, &e);
  if (rc) fprintf(stderr, "build: %s\n", e.msg);
  return rc;
}

static void test_complete(void) {
  /* Every step answered; one command per step, some repeated (a slow
   * client), a step with a newer command than the one before. */
  uint64_t seqs[] = {1, 1, 2, 3, 3, 3, 5, 6, 7, 8};
  resim_tool_input_t in = {.fb = fbs, .cmd = cmds, .ncmd = make_cmds(10)};
  for (size_t k = 1; k <= 10; k++) fbs[in.nfb++] = fb(k, seqs[k - 1]);
  resim_schedule_stats_t st;
  CHECK(build(&in, 12, &st) == 0);
  CHECK(out[0] == -1);
  for (size_t k = 1; k <= 10; k++) CHECK(seq_at(&in, k) == seqs[k - 1]);
  CHECK(seq_at(&in, 11) == 8 && seq_at(&in, 12) == 8); /* held after the last feedback */
  CHECK(st.feedback_steps == 10 && st.gaps == 0 && st.ambiguous_steps == 0 && st.bridged_steps == 0);
  CHECK(st.missing_commands == 0 && st.conflicts == 0);
}

static void test_inactive_before_first(void) {
  resim_tool_input_t in = {.fb = fbs, .cmd = cmds, .ncmd = make_cmds(10)};
  fbs[in.nfb++] = fb(5, 1);
  fbs[in.nfb++] = fb(6, 2);
  resim_schedule_stats_t st;
  CHECK(build(&in, 8, &st) == 0);
  for (int k = 0; k < 5; k++) CHECK(out[k] == -1);
  CHECK(seq_at(&in, 5) == 1 && seq_at(&in, 6) == 2 && seq_at(&in, 8) == 2);
}

static void test_gap_same_seq(void) {
  /* Feedback lost at steps 4..6 while the command stayed 3: exact. */
  resim_tool_input_t in = {.fb = fbs, .cmd = cmds, .ncmd = make_cmds(10)};
  fbs[in.nfb++] = fb(3, 3);
  fbs[in.nfb++] = fb(7, 3);
  fbs[in.nfb++] = fb(8, 4);
  resim_schedule_stats_t st;
  CHECK(build(&in, 8, &st) == 0);
  for (int k = 3; k <= 7; k++) CHECK(seq_at(&in, k) == 3);
  CHECK(seq_at(&in, 8) == 4);
  CHECK(st.gaps == 1 && st.bridged_steps == 3 && st.ambiguous_steps == 0);
}

static void test_gap_timed(void) {
  /* Feedback at 10 (seq 10) and 15 (seq 15) only: commands 11..15 were
   * written 1 ms apart, so each step in between takes the command written
   * before its interpolated feedback time: 11, 12, 13, 14. */
  resim_tool_input_t in = {.fb = fbs, .cmd = cmds, .ncmd = make_cmds(20)};
  fbs[in.nfb++] = fb(10, 10);
  fbs[in.nfb++] = fb(15, 15);
  resim_schedule_stats_t st;
  CHECK(build(&in, 15, &st) == 0);
  for (uint64_t k = 10; k <= 15; k++) CHECK(seq_at(&in, k) == k);
  CHECK(st.gaps == 1 && st.ambiguous_steps == 4 && st.bridged_steps == 0);
}

static void test_gap_untimed(void) {
  /* No timestamps: hold the last known command through the gap. */
  resim_tool_input_t in = {.fb = fbs, .cmd = cmds, .ncmd = make_cmds(20)};
  fbs[in.nfb++] = (resim_fb_t){.step = 10, .seq = 10};
  fbs[in.nfb++] = (resim_fb_t){.step = 15, .seq = 15};
  resim_schedule_stats_t st;
  CHECK(build(&in, 15, &st) == 0);
  for (uint64_t k = 10; k < 15; k++) CHECK(seq_at(&in, k) == 10);
  CHECK(seq_at(&in, 15) == 15);
  CHECK(st.ambiguous_steps == 4);
}

static void test_release(void) {
  /* Tool active 1..5 with seq 5, its feedback lost at 4..5, released at the
   * event of step 5 (inactive from 6), back at 9 with seq 6. */
  resim_tool_input_t in = {.fb = fbs, .cmd = cmds, .ncmd = make_cmds(10), .release = rels};
  fbs[in.nfb++] = fb(3, 5);
  fbs[in.nfb++] = fb(9, 6);
  rels[in.nrelease++] = 5;
  resim_schedule_stats_t st;
  CHECK(build(&in, 10, &st) == 0);
  CHECK(seq_at(&in, 3) == 5 && seq_at(&in, 4) == 5 && seq_at(&in, 5) == 5);
  for (int k = 6; k <= 8; k++) CHECK(out[k] == -1);
  CHECK(seq_at(&in, 9) == 6 && seq_at(&in, 10) == 6);
  CHECK(st.releases == 1 && st.bridged_steps == 2 && st.ambiguous_steps == 0);

  /* A release after the last feedback ends the hold. */
  in = (resim_tool_input_t){.fb = fbs, .cmd = cmds, .ncmd = make_cmds(10), .release = rels};
  fbs[in.nfb++] = fb(2, 2);
  rels[in.nrelease++] = 4;
  CHECK(build(&in, 8, &st) == 0);
  CHECK(seq_at(&in, 4) == 2 && out[5] == -1 && out[8] == -1);
  CHECK(st.releases == 1);
}

static void test_missing_command(void) {
  /* Seq 5 never reached the recorder: the nearest recorded below (4)
   * stands in, counted once however many steps used it. */
  resim_tool_input_t in = {.fb = fbs, .cmd = cmds, .ncmd = make_cmds(10)};
  memmove(&cmds[4], &cmds[5], 5 * sizeof cmds[0]); /* drop seq 5 */
  in.ncmd = 9;
  fbs[in.nfb++] = fb(1, 5);
  fbs[in.nfb++] = fb(2, 5);
  fbs[in.nfb++] = fb(3, 6);
  resim_schedule_stats_t st;
  CHECK(build(&in, 3, &st) == 0);
  CHECK(seq_at(&in, 1) == 4 && seq_at(&in, 2) == 4 && seq_at(&in, 3) == 6);
  CHECK(st.missing_commands == 1);
  /* Below every recorded seq: the first recorded one. */
  in = (resim_tool_input_t){.fb = fbs, .cmd = cmds + 3, .ncmd = 3};
  fbs[in.nfb++] = fb(1, 1);
  CHECK(build(&in, 1, &st) == 0);
  CHECK(out[1] == 0 && st.missing_commands == 1);
}

static void test_garbage(void) {
  /* Unsorted, duplicated with a conflict (the later-written wins), step 0
   * and steps beyond the range: no out-of-bounds, sensible result. */
  resim_tool_input_t in = {.fb = fbs, .cmd = cmds, .ncmd = make_cmds(10)};
  fbs[in.nfb++] = fb(4, 4);
  fbs[in.nfb++] = fb(2, 2);
  resim_fb_t late = fb(2, 3);
  late.wall_ns += 10;
  fbs[in.nfb++] = late;
  fbs[in.nfb++] = fb(0, 9);
  fbs[in.nfb++] = fb(1000000, 9);
  fbs[in.nfb++] = fb(3, 3);
  resim_schedule_stats_t st;
  CHECK(build(&in, 5, &st) == 0);
  CHECK(out[0] == -1 && out[1] == -1);
  CHECK(seq_at(&in, 2) == 3 && seq_at(&in, 3) == 3 && seq_at(&in, 4) == 4 && seq_at(&in, 5) == 4);
  CHECK(st.conflicts == 1 && st.feedback_steps == 3);

  /* Feedback but no command recorded: an error naming it. */
  in = (resim_tool_input_t){.fb = fbs, .cmd = cmds, .ncmd = 0};
  fbs[in.nfb++] = fb(1, 1);
  verr_t e;
  memset(&st, 0, sizeof st);
  CHECK(resim_schedule_build(&in, 3, out, &st, &e) == -1);
  CHECK(strstr(e.msg, "no ToolCommand") != NULL);
  /* Nothing at all: inactive throughout. */
  in = (resim_tool_input_t){0};
  CHECK(build(&in, 3, &st) == 0);
  CHECK(out[1] == -1 && out[3] == -1);
}

static uint32_t lcg(uint32_t *s) { return *s = *s * 1664525u + 1013904223u; }

static void test_dropped_feedback(void) {
  /* A client at ~1 kHz against a server at 1 kHz: the command of step k is
   * the newest written before the step, with jitter (0..2 commands per
   * step). Drop 30 % of the feedback, rebuild, and count wrong steps. */
  enum { N = 3000 };
  uint32_t rng = 12345;
  size_t ncmd = make_cmds(N + 10);
  static uint64_t truth[N + 1];
  uint64_t seq = 0;
  for (uint64_t k = 1; k <= N; k++) {
    uint32_t r = lcg(&rng) % 10;
    seq += r < 4 ? 0 : r < 9 ? 1 : 2; /* a client that sometimes misses or doubles a tick */
    if (seq == 0) seq = 1;
    truth[k] = seq;
  }
  /* Command timestamps consistent with that: command s written 0.1 ms
   * before the first step that applies it; a command never applied (two
   * in one step) 1 us before the one that overwrote it. */
  for (size_t i = 0; i < ncmd; i++) cmds[i].wall_ns = 0;
  for (uint64_t k = N; k >= 1; k--) cmds[truth[k] - 1].wall_ns = 1000000000 + ((int64_t)k - 1) * 1000000 + 100000;
  for (size_t i = truth[N]; i < ncmd; i++) cmds[i].wall_ns = cmds[i - 1].wall_ns + 1000000;
  for (size_t i = truth[N]; i-- > 0;)
    if (cmds[i].wall_ns == 0) cmds[i].wall_ns = cmds[i + 1].wall_ns - 1000;
  resim_tool_input_t in = {.fb = fbs, .cmd = cmds, .ncmd = ncmd};
  size_t kept = 0;
  for (uint64_t k = 1; k <= N; k++)
    if (k == 1 || k == N || lcg(&rng) % 10 >= 3) {
      fbs[in.nfb] = fb(k, truth[k]);
      fbs[in.nfb++].wall_ns += (int64_t)(lcg(&rng) % 300000); /* server jitter up to 0.3 ms */
      kept++;
    }
  resim_schedule_stats_t st;
  CHECK(build(&in, N, &st) == 0);
  uint64_t wrong = 0, wrong_in_certain = 0;
  for (uint64_t k = 1; k <= N; k++)
    if (seq_at(&in, k) != truth[k]) wrong++;
  CHECK(st.feedback_steps == kept);
  CHECK(st.bridged_steps + st.ambiguous_steps == N - kept);
  /* Every wrong step lies in an ambiguous gap: none where both sides
   * name the same command. */
  for (size_t i = 0; i + 1 < in.nfb; i++) {
    const resim_fb_t *a = &in.fb[i], *b = &in.fb[i + 1];
    if (a->seq != b->seq) continue;
    for (uint64_t k = a->step; k <= b->step; k++)
      if (seq_at(&in, k) != truth[k]) wrong_in_certain++;
  }
  CHECK(wrong_in_certain == 0);
  CHECK(st.bridged_steps > 0 && st.ambiguous_steps > 0); /* both kinds of gap occurred */
  CHECK(wrong <= st.ambiguous_steps);
  /* The timestamps make the estimate good: most ambiguous steps right. */
  CHECK(wrong * 4 <= st.ambiguous_steps);
  printf("dropped feedback: %zu of %d steps answered, %llu bridged, %llu ambiguous, %llu wrong\n", kept, N,
         (unsigned long long)st.bridged_steps, (unsigned long long)st.ambiguous_steps, (unsigned long long)wrong);
}

int main(void) {
  test_complete();
  test_inactive_before_first();
  test_gap_same_seq();
  test_gap_timed();
  test_gap_untimed();
  test_release();
  test_missing_command();
  test_garbage();
  test_dropped_feedback();
  return check_report("test_resim_schedule");
}
