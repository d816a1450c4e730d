/* SPDX-License-Identifier: Apache-2.0 */
/* Loss detection bookkeeping of the haptic client: the feedback slot clears
 * the contact the moment the server's writer is lost, fed with the status
 * values Cyclone's liveliness-changed listener delivers (the server's side
 * is tests/server/session/test_liveliness_watch.c). The DDS path itself is
 * covered by the `liveliness` integration test. */
#include <string.h>

#include "check.h"
#include "feedback_slot.h"
#include "test_dds.h"

static void test_slot(void) {
  feedback_slot_t s;
  CHECK(feedback_slot_init(&s, 0, 16) == 0);
  /* A pressed contact in the slot, as the data listener leaves it. */
  s.model.in_contact = 1;
  s.model.stiffness = 400;
  s.model.normal[2] = 1;
  s.model.proxy[2] = 0.01;
  s.arrival_mono_ns = 5000000;
  uint64_t lost_ns = 0, last = 0;
  dds_liveliness_changed_status_t st = test_liveliness_status(1, 0, 1, 0, 7);
  feedback_slot_liveliness(&s, &st, 1000);
  CHECK(!feedback_slot_server_lost(&s, &lost_ns, &last));
  /* The server dies: the very next read renders no wall. */
  st = test_liveliness_status(0, 1, -1, 1, 7);
  feedback_slot_liveliness(&s, &st, 35000000);
  contact_model_t m;
  feedback_slot_read(&s, &m);
  CHECK(m.in_contact == 0);
  double x[3] = {0, 0, 0}, v[3] = {0, 0, 0}, f[3];
  m.damping = 0;
  CHECK(contact_model_force(&m, x, v, 4, f) == 0);
  CHECK(feedback_slot_server_lost(&s, &lost_ns, &last));
  CHECK(lost_ns == 35000000 && last == 5000000);
  CHECK(s.lost_events == 1);
  /* One of two servers going away is not a loss. */
  st = test_liveliness_status(1, 0, 1, -1, 8);
  feedback_slot_liveliness(&s, &st, 40000000);
  CHECK(!feedback_slot_server_lost(&s, &lost_ns, &last));
  CHECK(s.regained_events == 1);
  s.model.in_contact = 1;
  st = test_liveliness_status(1, 0, 1, 0, 9); /* a second writer joins: alive 2 */
  st.alive_count = 2;
  feedback_slot_liveliness(&s, &st, 41000000);
  st = test_liveliness_status(1, 1, -1, 1, 8);
  feedback_slot_liveliness(&s, &st, 42000000);
  CHECK(!feedback_slot_server_lost(&s, &lost_ns, &last));
  feedback_slot_read(&s, &m);
  CHECK(m.in_contact == 1);
  feedback_slot_destroy(&s);
}

int main(void) {
  test_slot();
  return check_report("test_feedback_slot");
}
