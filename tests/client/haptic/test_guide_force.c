/* SPDX-License-Identifier: Apache-2.0 */
/* Guiding hand, client side (idl ToolRole): the force law each coupled
 * client renders (guide_force), its fallbacks and clamps, its passivity at
 * 1 kHz; the slot the DDS listeners fill (role validation, peer choice,
 * age); the latency filter that counts only our own commands' echoes; the
 * log lines and summary. The DDS path is covered by the guiding_hand
 * integration test. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "feedback_slot.h"
#include "guide_force.h"
#include "guide_report.h"
#include "guide_slot.h"

static guide_role_t role(const char *owner, const char *guide, double a, double k) {
  guide_role_t r;
  memset(&r, 0, sizeof r);
  r.known = 1;
  r.version = 1;
  snprintf(r.owner, sizeof r.owner, "%s", owner);
  snprintf(r.guide, sizeof r.guide, "%s", guide);
  r.authority = a;
  r.coupling_stiffness = k;
  return r;
}

static const contact_model_t FREE = {0};

static guide_input_t input(const guide_role_t *r, const char *own, const double x[3], const double peer[3],
                           const contact_model_t *m) {
  guide_input_t in;
  memset(&in, 0, sizeof in);
  in.role = r;
  in.own_station = own;
  memcpy(in.x, x, sizeof in.x);
  if (peer) {
    in.have_peer = 1;
    memcpy(in.peer, peer, sizeof in.peer);
    in.peer_age_s = 0.01;
  }
  in.server_silent_s = 0.001;
  in.contact = m;
  in.max_force = 10;
  in.period_s = 1e-3;
  return in;
}

static void test_sides(void) {
  guide_role_t r = role("", "bob", 0.5, 200);
  CHECK(guide_side_of(&r, "bob") == GUIDE_SIDE_GUIDE);
  CHECK(guide_side_of(&r, "alice") == GUIDE_SIDE_OWNER); /* owner "": anyone but the guide */
  CHECK(guide_side_of(&r, "") == GUIDE_SIDE_OWNER);
  CHECK(guide_is_peer(&r, GUIDE_SIDE_OWNER, "bob") && !guide_is_peer(&r, GUIDE_SIDE_OWNER, "carol"));
  CHECK(guide_is_peer(&r, GUIDE_SIDE_GUIDE, "alice") && guide_is_peer(&r, GUIDE_SIDE_GUIDE, "carol"));
  CHECK(!guide_is_peer(&r, GUIDE_SIDE_GUIDE, "bob"));
  CHECK_NEAR(guide_own_share(&r, GUIDE_SIDE_OWNER), 0.5, 0);
  r = role("alice", "bob", 0.8, 200);
  CHECK(guide_side_of(&r, "alice") == GUIDE_SIDE_OWNER);
  CHECK(guide_side_of(&r, "carol") == GUIDE_SIDE_NONE); /* a spectator of an assigned tool */
  CHECK(guide_is_peer(&r, GUIDE_SIDE_GUIDE, "alice") && !guide_is_peer(&r, GUIDE_SIDE_GUIDE, "carol"));
  CHECK_NEAR(guide_own_share(&r, GUIDE_SIDE_OWNER), 0.2, 1e-12);
  CHECK_NEAR(guide_own_share(&r, GUIDE_SIDE_GUIDE), 0.8, 1e-12);
  /* No guide, unknown role, bad numbers, owner = guide: nobody is coupled. */
  r = role("alice", "", 0, 0);
  CHECK(guide_side_of(&r, "alice") == GUIDE_SIDE_NONE);
  r = role("", "bob", 0.5, 200);
  r.known = 0;
  CHECK(guide_side_of(&r, "bob") == GUIDE_SIDE_NONE);
  r = role("", "bob", 1.5, 200);
  CHECK(guide_side_of(&r, "bob") == GUIDE_SIDE_NONE);
  r = role("", "bob", NAN, 200);
  CHECK(guide_side_of(&r, "bob") == GUIDE_SIDE_NONE);
  r = role("", "bob", 0.5, 0);
  CHECK(guide_side_of(&r, "bob") == GUIDE_SIDE_NONE);
  r = role("", "bob", 0.5, INFINITY);
  CHECK(guide_side_of(&r, "bob") == GUIDE_SIDE_NONE);
  r = role("bob", "bob", 0.5, 200);
  CHECK(guide_side_of(&r, "bob") == GUIDE_SIDE_NONE);
}

/* The integration test's numbers: A and B 2 cm apart in free space. */
static void test_free_space_coupling(void) {
  double A[3] = {0.012, 0.004, 0.07}, B[3] = {0.032, 0.004, 0.07};
  guide_output_t o;
  /* Authority 0.5: each feels 0.5 * 200 * 0.02 = 2 N towards the other. */
  guide_role_t r = role("", "bob", 0.5, 200);
  guide_input_t in = input(&r, "alice", A, B, &FREE);
  guide_force(&in, &o);
  CHECK(o.coupled && o.side == GUIDE_SIDE_OWNER);
  CHECK_NEAR(o.f[0], 2.0, 1e-9);
  CHECK_NEAR(o.f[1], 0, 1e-12);
  CHECK_NEAR(o.f[2], 0, 1e-12);
  CHECK_NEAR(o.x_tool[0], 0.022, 1e-12); /* where the server puts the tool */
  in = input(&r, "bob", B, A, &FREE);
  guide_force(&in, &o);
  CHECK(o.coupled && o.side == GUIDE_SIDE_GUIDE);
  CHECK_NEAR(o.f[0], -2.0, 1e-9);
  /* Take-over: the trainee is pulled with the whole spring, the instructor
   * feels the tool alone (nothing in free space). */
  r = role("alice", "bob", 1, 200);
  in = input(&r, "alice", A, B, &FREE);
  guide_force(&in, &o);
  CHECK(o.coupled);
  CHECK_NEAR(o.f[0], 4.0, 1e-9);
  CHECK_NEAR(o.magnitude, 4.0, 1e-9);
  in = input(&r, "bob", B, A, &FREE);
  guide_force(&in, &o);
  CHECK(o.coupled);
  CHECK_NEAR(o.magnitude, 0, 1e-12);
  /* Authority 0: the guide is the one pulled, the owner feels nothing. */
  r = role("alice", "bob", 0, 200);
  in = input(&r, "bob", B, A, &FREE);
  guide_force(&in, &o);
  CHECK_NEAR(o.f[0], -4.0, 1e-9);
  in = input(&r, "alice", A, B, &FREE);
  guide_force(&in, &o);
  CHECK_NEAR(o.magnitude, 0, 1e-12);
}

static void test_fallbacks_and_clamps(void) {
  double A[3] = {0, 0, 0}, B[3] = {0.02, 0, 0};
  guide_role_t r = role("", "bob", 0.5, 200);
  guide_output_t o;
  /* Peer older than 100 ms: plain rendering (nothing in free space). */
  guide_input_t in = input(&r, "alice", A, B, &FREE);
  in.peer_age_s = 0.15;
  guide_force(&in, &o);
  CHECK(!o.coupled && o.side == GUIDE_SIDE_OWNER && o.magnitude == 0);
  CHECK(o.why && strcmp(o.why, "peer silent") == 0);
  in.peer_age_s = 0.099;
  guide_force(&in, &o);
  CHECK(o.coupled);
  /* The server silent for longer than 250 ms (lost), or never heard: no
   * coupling; a shorter feedback gap keeps it. */
  in = input(&r, "alice", A, B, &FREE);
  in.server_silent_s = 0.2;
  guide_force(&in, &o);
  CHECK(o.coupled);
  in.server_silent_s = 0.3;
  guide_force(&in, &o);
  CHECK(!o.coupled && o.magnitude == 0);
  CHECK(o.why && strcmp(o.why, "server silent") == 0);
  in.server_silent_s = -1;
  guide_force(&in, &o);
  CHECK(!o.coupled && o.magnitude == 0);
  /* No peer, a corrupt peer position: plain. */
  in = input(&r, "alice", A, NULL, &FREE);
  guide_force(&in, &o);
  CHECK(!o.coupled && o.magnitude == 0);
  double nan_peer[3] = {NAN, 0, 0};
  in = input(&r, "alice", A, nan_peer, &FREE);
  guide_force(&in, &o);
  CHECK(!o.coupled && o.magnitude == 0 && isfinite(o.f[0]));
  /* A peer 1 m away: clamped to the device, direction kept. */
  double far[3] = {0.6, 0.8, 0};
  in = input(&r, "alice", A, far, &FREE);
  in.max_force = 3;
  guide_force(&in, &o);
  CHECK_NEAR(o.magnitude, 3, 1e-9);
  CHECK_NEAR(o.f[0], 1.8, 1e-9);
  CHECK_NEAR(o.f[1], 2.4, 1e-9);
  /* A device rated 100 N/m renders the 200 N/m coupling at 100 N/m. */
  in = input(&r, "alice", A, B, &FREE);
  in.max_stiffness = 100;
  guide_force(&in, &o);
  CHECK_NEAR(o.k, 100, 0);
  CHECK_NEAR(o.f[0], 1.0, 1e-9);
  /* Damping on own velocity: moving towards the peer at 0.1 m/s lowers
   * the pull by (1 - w) k T v = 0.5 * 200 * 1e-3 * 0.1. */
  in = input(&r, "alice", A, B, &FREE);
  in.v[0] = 0.1;
  guide_force(&in, &o);
  CHECK_NEAR(o.f[0], 2.0 - 0.01, 1e-9);
  /* Not in the role: plain contact at our own position even with a peer. */
  guide_role_t other = role("carol", "bob", 0.5, 200);
  contact_model_t wall = {1, {0, 0, 0.01}, {0, 0, 1}, 400, 0.4, 0};
  in = input(&other, "alice", A, B, &wall);
  guide_force(&in, &o);
  CHECK(!o.coupled && o.side == GUIDE_SIDE_NONE);
  CHECK(o.why && strcmp(o.why, "not in the role") == 0);
  CHECK_NEAR(o.f[2], 4.0, 1e-9);
  double f_plain[3];
  contact_model_force(&wall, A, NULL, 10, f_plain);
  CHECK_NEAR(o.f[2], f_plain[2], 1e-12);
}

/* Contact is evaluated where the server puts the tool, and each side feels
 * its share of it. */
static void test_contact_share(void) {
  contact_model_t wall = {1, {0, 0, 0}, {0, 0, 1}, 400, 0.4, 0}; /* surface z = 0, outward +z */
  guide_role_t r = role("", "bob", 0.5, 200);
  guide_output_t o;
  /* Both hands 1 cm deep: tool 1 cm deep, 4 N of tissue, 2 N each. */
  double own[3] = {0, 0, -0.01}, peer[3] = {0, 0, -0.01};
  guide_input_t in = input(&r, "alice", own, peer, &wall);
  guide_force(&in, &o);
  CHECK_NEAR(o.f[2], 2.0, 1e-9);
  /* Own hand 1 cm deep, the peer's 1 cm above: the tool is on the surface,
   * no tissue force; the spring pulls up with 0.5 * 200 * 0.02. */
  double above[3] = {0, 0, 0.01};
  in = input(&r, "alice", own, above, &wall);
  guide_force(&in, &o);
  CHECK_NEAR(o.x_tool[2], 0, 1e-12);
  CHECK_NEAR(o.f[2], 2.0, 1e-9);
  /* Take-over with the instructor pressing 1 cm: he feels the whole tissue,
   * the trainee (hand above) only the pull down towards him. */
  r = role("alice", "bob", 1, 200);
  in = input(&r, "bob", own, above, &wall);
  guide_force(&in, &o);
  CHECK_NEAR(o.f[2], 4.0, 1e-9);
  in = input(&r, "alice", above, own, &wall);
  guide_force(&in, &o);
  CHECK_NEAR(o.f[2], -4.0, 1e-9);
}

/* A light hand (50 g) let go 2 cm from a still peer, force held for each
 * 1 ms tick (zero-order hold) as a device does: with the coupling's damping
 * the energy decays; without it (period 0 passed: no damping) the same
 * sampled spring gains energy. Checks the damping is what keeps it passive. */
static double coupled_energy_after(double period_for_damping, double seconds) {
  guide_role_t r = role("", "bob", 1, 200); /* take-over: the owner gets the whole spring */
  double x = 0.02, v = 0, m = 0.05, k = 200, T = 1e-3;
  double peer[3] = {0, 0, 0};
  for (int tick = 0; tick < (int)(seconds / T); tick++) {
    double pos[3] = {x, 0, 0};
    guide_input_t in = input(&r, "alice", pos, peer, &FREE);
    in.v[0] = v;
    in.period_s = period_for_damping;
    guide_output_t o;
    guide_force(&in, &o);
    /* Exact motion under a constant force over the tick, in fine steps. */
    for (int s = 0; s < 100; s++) {
      v += o.f[0] / m * (T / 100);
      x += v * (T / 100);
    }
  }
  return 0.5 * m * v * v + 0.5 * k * x * x;
}

static void test_passive(void) {
  double e0 = 0.5 * 200 * 0.02 * 0.02;
  double damped = coupled_energy_after(1e-3, 2.0), undamped = coupled_energy_after(0, 2.0);
  printf("coupling energy after 2 s: %.3g J damped, %.3g J undamped (start %.3g J)\n", damped, undamped, e0);
  CHECK(damped < e0);
  CHECK(undamped > e0);
}

static void test_slot(void) {
  guide_slot_t s;
  CHECK(guide_slot_init(&s, 2) == 0);
  viscera_ToolRole tr;
  memset(&tr, 0, sizeof tr);
  tr.tool_id = 2;
  tr.version = 3;
  strcpy(tr.owner, "*");
  strcpy(tr.guide, "bob");
  tr.authority = 0.5f;
  tr.coupling_stiffness = 200;
  CHECK(guide_slot_role(&s, &tr) == 1);
  CHECK(s.role.owner[0] == 0 && strcmp(s.role.guide, "bob") == 0 && s.role.version == 3);
  /* Another tool's role is not ours. */
  tr.tool_id = 1;
  CHECK(guide_slot_role(&s, &tr) == 0);
  tr.tool_id = 2;
  /* Refused, the previous role stays: a bad station name, an authority out
   * of range, a non-finite stiffness, an unterminated name. */
  strcpy(tr.guide, "bo b");
  CHECK(guide_slot_role(&s, &tr) == -1);
  strcpy(tr.guide, "bob");
  tr.authority = 2;
  CHECK(guide_slot_role(&s, &tr) == -1);
  tr.authority = 0.5f;
  tr.coupling_stiffness = NAN;
  CHECK(guide_slot_role(&s, &tr) == -1);
  tr.coupling_stiffness = 200;
  memset(tr.owner, 'a', sizeof tr.owner);
  CHECK(guide_slot_role(&s, &tr) == -1);
  CHECK(s.roles_rejected == 4 && s.role.version == 3 && strcmp(s.role.guide, "bob") == 0);
  /* Peers: alice's view shows bob's latest position and its age; bob's
   * view the most recent non-guide station's (owner ""). */
  float pb[3] = {0.03f, 0, 0.07f}, pa[3] = {0.01f, 0, 0.07f}, pc[3] = {0.02f, 0, 0.07f};
  CHECK(guide_slot_command(&s, "bob", pb, 1000000) == 0);
  CHECK(guide_slot_command(&s, "alice", pa, 2000000) == 0);
  CHECK(guide_slot_command(&s, "carol", pc, 3000000) == 0);
  float bad[3] = {0, NAN, 0};
  CHECK(guide_slot_command(&s, "bob", bad, 4000000) == -1 && s.bad_samples == 1);
  guide_view_t v;
  guide_slot_read(&s, "alice", 51000000, &v);
  CHECK(v.have_peer && strcmp(v.peer_station, "bob") == 0);
  CHECK_NEAR(v.peer[0], 0.03, 1e-7);
  CHECK_NEAR(v.peer_age_s, 0.05, 1e-12);
  /* The peer's transit (source timestamp to our clock): unknown at first,
   * then the first value, then smoothed; clocks apart are ignored. */
  CHECK(v.peer_transit_s < 0);
  guide_slot_transit(&s, "bob", 0.100);
  guide_slot_transit(&s, "bob", -0.5);                    /* the writer's clock ahead of ours */
  guide_slot_transit(&s, "bob", GUIDE_TRANSIT_MAX_S + 1); /* or far behind */
  guide_slot_read(&s, "alice", 51000000, &v);
  CHECK_NEAR(v.peer_transit_s, 0.100, 1e-12);
  guide_slot_transit(&s, "bob", 0.200);
  guide_slot_read(&s, "alice", 51000000, &v);
  CHECK_NEAR(v.peer_transit_s, 0.100 + GUIDE_TRANSIT_GAIN * 0.100, 1e-12);
  guide_slot_read(&s, "bob", 51000000, &v);
  CHECK(v.have_peer && strcmp(v.peer_station, "carol") == 0);
  /* Once assigned to alice, carol is nobody's peer. */
  strcpy(tr.owner, "alice");
  tr.version = 4;
  CHECK(guide_slot_role(&s, &tr) == 1);
  guide_slot_read(&s, "bob", 51000000, &v);
  CHECK(v.have_peer && strcmp(v.peer_station, "alice") == 0);
  guide_slot_read(&s, "carol", 51000000, &v);
  CHECK(!v.have_peer);
  /* More stations than entries: the stalest is replaced, the rest kept. */
  for (int i = 0; i < GUIDE_SLOT_STATIONS; i++) {
    char name[16];
    snprintf(name, sizeof name, "s%d", i);
    guide_slot_command(&s, name, pc, 5000000 + (uint64_t)i);
  }
  guide_slot_read(&s, "alice", 6000000, &v);
  CHECK(!v.have_peer); /* bob's entry was the stalest */
  guide_slot_command(&s, "bob", pb, 7000000);
  guide_slot_read(&s, "alice", 7000000, &v);
  CHECK(v.have_peer && v.peer_age_s == 0 && v.peer_transit_s < 0); /* a new entry: transit unknown again */
  /* The server disposed the role: nobody is coupled. */
  guide_slot_role_lost(&s);
  guide_slot_read(&s, "alice", 7000000, &v);
  CHECK(!v.role.known && !v.have_peer);
  guide_slot_destroy(&s);
}

static void test_own_echoes_only(void) {
  static feedback_slot_t s;
  CHECK(feedback_slot_init(&s, 0, 16) == 0);
  feedback_slot_sent(&s, 5, 1000000);
  viscera_ContactFeedback fb;
  memset(&fb, 0, sizeof fb);
  fb.normal[2] = 1;
  fb.stiffness = 400;
  /* The echo of another station's command (the owner's, seen by the
   * guide): rendered, but no latency sample. */
  fb.cmd_seq = 77;
  fb.cmd_client_mono_ns = 900000;
  CHECK(feedback_slot_accept(&s, &fb, 1200000) == 1);
  CHECK(s.nlatency == 0 && s.foreign_echoes == 1 && s.received == 1);
  /* Same seq as ours but another send time: not ours either. */
  fb.cmd_seq = 5;
  fb.cmd_client_mono_ns = 999999;
  feedback_slot_accept(&s, &fb, 1200000);
  CHECK(s.nlatency == 0 && s.foreign_echoes == 2);
  /* Ours: 300 us round trip, counted once however often it is echoed. */
  fb.cmd_client_mono_ns = 1000000;
  feedback_slot_accept(&s, &fb, 1300000);
  feedback_slot_accept(&s, &fb, 1400000);
  CHECK(s.nlatency == 1);
  CHECK_NEAR(s.latency_us[0], 300, 1e-9);
  /* A corrupt plane is refused. */
  fb.stiffness = NAN;
  CHECK(feedback_slot_accept(&s, &fb, 1500000) == -1 && s.rejected == 1);
  feedback_slot_destroy(&s);
}

static void test_report(void) {
  FILE *log = tmpfile();
  CHECK(log != NULL);
  if (!log) return;
  guide_report_t rep;
  CHECK(guide_report_init(&rep, 1000) == 0);
  guide_role_t none = {0};
  guide_role_t r = role("", "bob", 0.5, 200);
  guide_output_t plain = {.w = 1, .why = "peer silent"},
                 coupled = {.coupled = 1, .side = GUIDE_SIDE_OWNER, .w = 0.5, .k = 200};
  guide_report_tick(&rep, 0.001, &none, "", 0, &plain, log);
  for (int i = 0; i < 1500; i++) guide_report_tick(&rep, 1.0 + i * 1e-3, &r, "bob", (i % 4) * 1e-3, &coupled, log);
  r.version = 2;
  r.authority = 1;
  coupled.w = 0;
  guide_report_tick(&rep, 2.5, &r, "bob", 0, &coupled, log);
  guide_report_tick(&rep, 3.0, &r, "bob", 0.5, &plain, log);
  CHECK_NEAR(guide_report_coupled_s(&rep, 1e-3), 1.501, 1e-9);
  guide_report_summary(&rep, 1e-3, log);
  rewind(log);
  char text[2048] = {0};
  size_t n = fread(text, 1, sizeof text - 1, log);
  text[n] = 0;
  fclose(log);
  printf("%s", text);
  CHECK(strstr(text, "t=1.000 s guide: coupled as owner (trainee), own share 0.50, k 200 N/m, peer bob") != NULL);
  CHECK(strstr(text, "t=2.500 s guide: coupled as owner (trainee), own share 0.00") != NULL);
  CHECK(strstr(text, "t=3.000 s guide: not coupled (peer silent; role v2: owner '', guide 'bob')") != NULL);
  CHECK(strstr(text, "GUIDE coupled 1.5 s as owner (trainee), 0.0 s as guide (instructor); last: as owner "
                     "(trainee), authority 1.00, k 200 N/m, peer bob") != NULL);
  CHECK(strstr(text, "no role") == NULL); /* nothing to say before a role arrives */
  /* Ages sampled on the 1000 coupled ticks the capacity holds (0..3 ms),
   * none from the uncoupled tick. */
  CHECK(strstr(text, "peer position age when rendered (since its arrival): median 2000 us, p99 3000 us, max 3000 us "
                     "(1000 ticks)") != NULL);
  guide_report_free(&rep);
  /* Exactly three lines of changes plus the two summary lines. */
  int lines = 0;
  for (char *p = text; *p; p++) lines += *p == '\n';
  CHECK(lines == 5);
}

int main(void) {
  test_sides();
  test_free_space_coupling();
  test_fallbacks_and_clamps();
  test_contact_share();
  test_passive();
  test_slot();
  test_own_echoes_only();
  test_report();
  return check_report("test_guide_force");
}
