/* SPDX-License-Identifier: Apache-2.0 */
/* The feedback slot's newest-wins order and value limits (issue 14.2 and
 * 15.2): per writer, a ContactFeedback whose seq is not above the last one
 * taken is never used after it (best effort may deliver out of order); a
 * plane stiffer, or a force larger, than the scene gives the tool is
 * refused; another tool's sample is not ours. The identity of the writer
 * (seat_server.c) is covered by the `impostor` integration test. */
#include <string.h>

#include "check.h"
#include "feedback_slot.h"

static viscera_ContactFeedback sample(uint64_t seq, float proxy_z) {
  viscera_ContactFeedback fb;
  memset(&fb, 0, sizeof fb);
  fb.tool_id = 0;
  fb.seq = seq;
  fb.in_contact = 1;
  fb.proxy_position[2] = proxy_z;
  fb.normal[2] = 1;
  fb.stiffness = 400;
  fb.force[2] = 2;
  return fb;
}

static void test_newest_wins(void) {
  feedback_slot_t s;
  CHECK(feedback_slot_init(&s, 0, 16) == 0);
  contact_model_t m;
  viscera_ContactFeedback a = sample(10, 0.010f), b = sample(11, 0.011f), c = sample(12, 0.012f);
  /* Arrival order 10, 12, 11 (reordered): 11 comes after 12 and is skipped. */
  CHECK(feedback_slot_accept_from(&s, &a, 7, 1000) == 1);
  CHECK(feedback_slot_accept_from(&s, &c, 7, 2000) == 1);
  CHECK(feedback_slot_accept_from(&s, &b, 7, 3000) == -2);
  feedback_slot_read(&s, &m);
  CHECK_NEAR(m.proxy[2], 0.012, 1e-6);
  CHECK(s.stale == 1 && s.received == 2);
  /* A duplicate is not newer either. */
  CHECK(feedback_slot_accept_from(&s, &c, 7, 4000) == -2 && s.stale == 2);
  /* A new writer (a restarted server) starts its own count from 1. */
  viscera_ContactFeedback d = sample(1, 0.020f);
  CHECK(feedback_slot_accept_from(&s, &d, 8, 5000) == 1);
  feedback_slot_read(&s, &m);
  CHECK_NEAR(m.proxy[2], 0.020, 1e-6);
  /* Without a writer (unit callers) no order is kept. */
  CHECK(feedback_slot_accept(&s, &a, 6000) == 1);
  feedback_slot_destroy(&s);
}

static void test_limits(void) {
  feedback_slot_t s;
  CHECK(feedback_slot_init(&s, 0, 16) == 0);
  feedback_slot_set_limits(&s, 400, 4);
  viscera_ContactFeedback ok = sample(1, 0.01f), stiff = sample(2, 0.01f), strong = sample(3, 0.01f);
  stiff.stiffness = 1e5f;
  strong.force[2] = -4.5f;
  CHECK(feedback_slot_accept_from(&s, &ok, 7, 1000) == 1);
  CHECK(feedback_slot_accept_from(&s, &stiff, 7, 2000) == -1);
  CHECK(feedback_slot_accept_from(&s, &strong, 7, 3000) == -1);
  CHECK(s.out_of_limits == 2 && s.rejected == 2);
  /* The maximum itself is allowed (the server clamps to it). */
  viscera_ContactFeedback at_max = sample(4, 0.01f);
  at_max.force[2] = 4;
  CHECK(feedback_slot_accept_from(&s, &at_max, 7, 4000) == 1);
  /* Not finite anywhere, force included: refused. */
  viscera_ContactFeedback nan = sample(5, 0.01f);
  nan.force[0] = NAN;
  CHECK(feedback_slot_accept_from(&s, &nan, 7, 5000) == -1);
  /* Another tool's sample is not ours. */
  viscera_ContactFeedback other = sample(6, 0.01f);
  other.tool_id = 1;
  CHECK(feedback_slot_accept_from(&s, &other, 7, 6000) == 0);
  feedback_slot_destroy(&s);
}

/* An echo of our own command whose proxy lies beyond the tool's reach
 * (shaft length + tip radius) from the tip we sent is a forgery: refused.
 * Within reach, or not our echo (no tip known), it is taken. */
static void test_reach(void) {
  feedback_slot_t s;
  CHECK(feedback_slot_init(&s, 0, 16) == 0);
  feedback_slot_set_limits(&s, 400, 4);
  feedback_slot_set_reach(&s, 0.103f);
  const double tip[3] = {0.01, 0.0, 0.03};
  feedback_slot_sent_at(&s, 5, 1000, tip);
  viscera_ContactFeedback far = sample(1, 0.5f), near = sample(2, 0.08f), foreign = sample(3, 0.5f);
  far.cmd_seq = near.cmd_seq = 5;
  far.cmd_client_mono_ns = near.cmd_client_mono_ns = 1000;
  far.proxy_position[0] = near.proxy_position[0] = 0.01f;
  CHECK(feedback_slot_accept_from(&s, &far, 7, 2000) == -1); /* 0.47 m from the tip */
  CHECK(s.out_of_limits == 1);
  CHECK(feedback_slot_accept_from(&s, &near, 7, 3000) == 1); /* 5 cm deep: within the shaft */
  foreign.cmd_seq = 6;                                       /* not an echo of ours: no tip to compare */
  foreign.cmd_client_mono_ns = 999;
  CHECK(feedback_slot_accept_from(&s, &foreign, 7, 4000) == 1);
  /* Without a known reach nothing is refused for distance. */
  feedback_slot_set_reach(&s, 0);
  viscera_ContactFeedback far2 = sample(4, 0.5f);
  far2.cmd_seq = 5;
  far2.cmd_client_mono_ns = 1000;
  CHECK(feedback_slot_accept_from(&s, &far2, 7, 5000) == 1);
  feedback_slot_destroy(&s);
}

int main(void) {
  test_newest_wins();
  test_limits();
  test_reach();
  return check_report("test_feedback_slot_order");
}
