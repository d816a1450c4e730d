/* SPDX-License-Identifier: Apache-2.0 */
/* test_command_playout: one command into effect per step however the
 * commands bunched (server/session/command_playout.h): a client whose
 * ticks meet the server's, late by a step at random, drives an even tool
 * path with depth 1 and a broken one with depth 0 (the server before the
 * playout); a burst beyond the depth is superseded; a command always
 * waiting is dropped after PLAYOUT_CATCHUP_STEPS to give the latency back;
 * the counters say what happened. Through tool_roles (the server's path):
 * the seq check against the newest waiting, a new writer, forgetting. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "scene.h"
#include "scene_expect.h"
#include "session/command_playout.h"
#include "session/tool_roles.h"

static tool_input_t tick(uint64_t seq) {
  tool_input_t c;
  memset(&c, 0, sizeof c);
  c.pos[0] = 1e-5 * (double)seq; /* 10 um per client tick: a 10 mm/s sweep */
  c.seq = seq;
  return c;
}

/* The client's tick k reaches step k, or step k + 1 when late[k]. The
 * server takes, then puts one into effect. Returns how many steps moved
 * the tool by other than one tick (held or jumped), after the first few. */
static int uneven_steps(size_t depth, const unsigned char *late, int nsteps, command_playout_t *p, int *answered) {
  uint64_t was = 0;
  int uneven = 0, have = 0;
  *answered = 0;
  for (int k = 1; k < nsteps; k++) {
    /* Arrivals at step k: tick k - 1 if it was late, then tick k if on time. */
    if (late[k - 1]) {
      tool_input_t c = tick((uint64_t)k - 1);
      command_playout_push(p, depth, &c);
    }
    if (!late[k]) {
      tool_input_t c = tick((uint64_t)k);
      command_playout_push(p, depth, &c);
    }
    tool_input_t now;
    if (command_playout_next(p, &now)) {
      (*answered)++;
      if (have && k > 10 && now.seq != was + 1) uneven++;
      was = now.seq;
      have = 1;
    } else if (have && k > 10) {
      uneven++; /* the tool held still */
    }
  }
  return uneven;
}

static void test_jitter(void) {
  enum { N = 4000 };
  static unsigned char late[N];
  srand(7);
  for (int k = 0; k < N; k++) late[k] = (unsigned char)(rand() % 2); /* ticks meet the step: half of them late */
  late[0] = 0;
  command_playout_t a, b;
  memset(&a, 0, sizeof a);
  memset(&b, 0, sizeof b);
  int ans0, ans1;
  int uneven0 = uneven_steps(0, late, N, &a, &ans0);
  int uneven1 = uneven_steps(1, late, N, &b, &ans1);
  fprintf(stderr,
          "  half the ticks late: depth 0 %d uneven steps, %d answered; depth 1 %d uneven, %d answered, %d catch-ups\n",
          uneven0, ans0, uneven1, ans1, (int)b.caught_up);
  CHECK(uneven0 > N / 5); /* the server before: a hold or a jump on about every other step */
  /* One step's wait absorbs it; what is left comes from the catch-ups (a
   * run of PLAYOUT_CATCHUP_STEPS ticks on time, then a late one: a jump,
   * and a hold and a jump to wait again). */
  CHECK(b.caught_up <= N / 200);
  CHECK(uneven1 <= 3 * (int)b.caught_up + 1);
  CHECK(ans1 >= N - 2 - (int)b.caught_up); /* N - 1 steps, a tick into effect in each but those and the first */
  CHECK(ans0 < N - N / 10);                /* where depth 0 skipped a quarter */
  CHECK(a.superseded > N / 10);            /* depth 0: a pair taken together keeps only the newer */
  CHECK(b.superseded == 0);
  CHECK(b.delayed > N / 4); /* the on-time ones waited a step */
  CHECK(a.delayed == 0);
}

static void test_catch_up(void) {
  /* One late tick, then every tick on time: the playout waits a step for
   * PLAYOUT_CATCHUP_STEPS steps, then drops one and answers at once. */
  command_playout_t p;
  memset(&p, 0, sizeof p);
  tool_input_t out;
  uint64_t seq = 1;
  command_playout_push(&p, 1, &(tool_input_t){.seq = seq});
  CHECK(command_playout_next(&p, &out) && out.seq == 1);
  CHECK(!command_playout_next(&p, &out)); /* tick 2 late: the tool holds */
  command_playout_push(&p, 1, &(tool_input_t){.seq = 2});
  command_playout_push(&p, 1, &(tool_input_t){.seq = 3});
  seq = 3;
  unsigned steps = 0;
  uint64_t prev = 1;
  int jumped_at = -1;
  for (; steps < 3 * PLAYOUT_CATCHUP_STEPS; steps++) {
    CHECK(command_playout_next(&p, &out));
    if (out.seq != prev + 1) {
      CHECK(jumped_at < 0); /* once */
      CHECK(out.seq == prev + 2);
      jumped_at = (int)steps;
    }
    prev = out.seq;
    command_playout_push(&p, 1, &(tool_input_t){.seq = ++seq});
  }
  fprintf(stderr, "  a step's wait given back after %d steps\n", jumped_at);
  CHECK(jumped_at == (int)PLAYOUT_CATCHUP_STEPS);
  CHECK(p.caught_up == 1 && p.superseded == 0);
  CHECK(p.delayed == PLAYOUT_CATCHUP_STEPS - 1); /* each waited a step until the catch-up, then none */
  CHECK(p.n == 1 && p.wait[0].seq == seq);
}

static void test_burst(void) {
  /* Four ticks at once after a stall: depth 1 keeps the newest two. */
  command_playout_t p;
  memset(&p, 0, sizeof p);
  for (uint64_t s = 1; s <= 4; s++) command_playout_push(&p, 1, &(tool_input_t){.seq = s});
  CHECK(p.n == 2 && p.superseded == 2);
  tool_input_t out;
  CHECK(command_playout_next(&p, &out) && out.seq == 3);
  CHECK(command_playout_next(&p, &out) && out.seq == 4);
  CHECK(!command_playout_next(&p, &out));
  CHECK(p.delayed == 1);
  /* Depth 0: the newest at once. */
  memset(&p, 0, sizeof p);
  for (uint64_t s = 1; s <= 4; s++) command_playout_push(&p, 0, &(tool_input_t){.seq = s});
  CHECK(command_playout_next(&p, &out) && out.seq == 4 && p.superseded == 3);
  /* A depth beyond the maximum is held to it. */
  memset(&p, 0, sizeof p);
  for (uint64_t s = 1; s <= 100; s++) command_playout_push(&p, 1000, &(tool_input_t){.seq = s});
  CHECK(p.n == PLAYOUT_MAX_DEPTH + 1);
  command_playout_clear(&p);
  CHECK(p.n == 0 && !command_playout_next(&p, &out) && p.superseded == 100 - (PLAYOUT_MAX_DEPTH + 1));
}

static void test_roles_path(void) {
  static const char yaml[] = "scene: playout\n"
                             "organs:\n"
                             "  - {name: kidney, mesh: k.obj}\n"
                             "tools:\n"
                             "  - {name: p0, stiffness: 300}\n";
  scene_t scene;
  verr_t err;
  CHECK(scene_loads(&scene, &err, yaml, "/base"));
  tool_roles_t r;
  tool_roles_init(&r, &scene);
  CHECK(r.playout_depth == PLAYOUT_DEFAULT_DEPTH && PLAYOUT_DEFAULT_DEPTH == 0); /* opt-in: no latency added */
  r.playout_depth = 1; /* viscera-server --command-playout 1 */
  tool_cmd_t c;
  memset(&c, 0, sizeof c);
  c.orientation[0] = 1;
  c.max_force = 5;
  tool_effective_t e;
  /* Two commands of one writer in one take: the older now, the newer next step. */
  c.seq = 1;
  tool_roles_note(&r, 0, TOOL_SIDE_OWNER, "", 11, &c, 0);
  c.seq = 2;
  c.position[0] = 0.002f;
  CHECK(!tool_roles_stale(&r, 0, TOOL_SIDE_OWNER, 11, 2));
  tool_roles_note(&r, 0, TOOL_SIDE_OWNER, "", 11, &c, 0);
  CHECK(tool_roles_effective(&r, 0, 0, &e) == 0); /* nothing in effect before the step's advance */
  CHECK(tool_roles_stale(&r, 0, TOOL_SIDE_OWNER, 11, 2) && tool_roles_stale(&r, 0, TOOL_SIDE_OWNER, 11, 1));
  CHECK(!tool_roles_stale(&r, 0, TOOL_SIDE_OWNER, 12, 1)); /* another writer has its own seq */
  CHECK(tool_roles_advance(&r) == 1u);
  CHECK(tool_roles_effective(&r, 0, 0, &e) == 1 && e.cmd.seq == 1 && e.cmd.pos[0] == 0);
  CHECK(tool_roles_side_of_writer(&r, 0, 11) == TOOL_SIDE_OWNER);
  CHECK(tool_roles_advance(&r) == 1u);
  CHECK(tool_roles_effective(&r, 0, 0, &e) == 1 && e.cmd.seq == 2 && e.cmd.pos[0] == (double)0.002f);
  CHECK(tool_roles_advance(&r) == 0); /* nothing waiting: the tool holds */
  /* A new writer (the client restarted) drops what the old one left waiting. */
  c.seq = 3;
  tool_roles_note(&r, 0, TOOL_SIDE_OWNER, "", 11, &c, 0);
  c.seq = 1;
  c.position[0] = 0.004f;
  tool_roles_note(&r, 0, TOOL_SIDE_OWNER, "", 12, &c, 0);
  CHECK(tool_roles_advance(&r) == 1u);
  CHECK(tool_roles_effective(&r, 0, 0, &e) == 1 && e.cmd.seq == 1 && e.cmd.pos[0] == (double)0.004f);
  CHECK(tool_roles_side_of_writer(&r, 0, 12) == TOOL_SIDE_OWNER && tool_roles_side_of_writer(&r, 0, 11) == -1);
  /* Forgetting keeps the counters in the totals. */
  uint64_t d, s, u;
  tool_roles_playout_totals(&r, &d, &s, &u);
  CHECK(d == 1 && s == 0 && u == 0);
  tool_roles_forget(&r, 0, TOOL_SIDE_OWNER);
  CHECK(tool_roles_advance(&r) == 0 && tool_roles_effective(&r, 0, 0, &e) == 0);
  tool_roles_playout_totals(&r, &d, &s, &u);
  CHECK(d == 1);
}

int main(void) {
  test_jitter();
  test_catch_up();
  test_burst();
  test_roles_path();
  return check_report("test_command_playout");
}
