/* Loss detection bookkeeping: the server's liveliness watch (which writers
 * to release) and the haptic client's feedback slot (clear the contact the
 * moment the server's writer is lost), fed with the status values Cyclone's
 * liveliness-changed listener delivers. The DDS path itself is covered by
 * the `liveliness` integration test. */
#include <string.h>

#include "check.h"
#include "feedback_slot.h"
#include "session/liveliness_watch.h"

static dds_liveliness_changed_status_t status(uint32_t alive, uint32_t not_alive, int32_t dalive, int32_t dnot,
                                              dds_instance_handle_t h) {
  dds_liveliness_changed_status_t s = {alive, not_alive, dalive, dnot, h};
  return s;
}

static void test_watch(void) {
  liveliness_watch_t w;
  liveliness_watch_init(&w);
  liveliness_lost_t e;
  CHECK(!liveliness_watch_pop(&w, 1000, 0, &e));
  /* A writer appears: nothing to release. */
  dds_liveliness_changed_status_t s = status(1, 0, 1, 0, 42);
  liveliness_watch_note(&w, &s, 100);
  CHECK(!liveliness_watch_pop(&w, 1000, 0, &e));
  CHECK(w.regained_total == 1);
  /* Its lease expires: alive -> not alive. */
  s = status(0, 1, -1, 1, 42);
  liveliness_watch_note(&w, &s, 200);
  /* Another writer is deleted while alive (clean exit). */
  s = status(0, 1, -1, 0, 43);
  liveliness_watch_note(&w, &s, 300);
  /* A not-alive writer is later removed altogether: not a new loss. */
  s = status(0, 0, 0, -1, 42);
  liveliness_watch_note(&w, &s, 400);
  /* Not handed out before the confirmation delay has passed. */
  CHECK(!liveliness_watch_pop(&w, 250, 100, &e));
  CHECK(liveliness_watch_pop(&w, 300, 100, &e));
  CHECK(e.writer == 42 && e.mono_ns == 200 && e.expired == 1 && e.regained == 0);
  CHECK(!liveliness_watch_pop(&w, 399, 100, &e));
  CHECK(liveliness_watch_pop(&w, 400, 100, &e));
  CHECK(e.writer == 43 && e.mono_ns == 300 && e.expired == 0);
  CHECK(!liveliness_watch_pop(&w, 1000, 0, &e));
  CHECK(w.lost_total == 2);
  /* A lapse followed by the same writer coming back (a starved receiver
   * catching up) is marked regained; another writer's return is not it. */
  s = status(0, 1, -1, 1, 50);
  liveliness_watch_note(&w, &s, 500);
  s = status(1, 1, 1, 0, 51);
  liveliness_watch_note(&w, &s, 505);
  s = status(1, 0, 1, -1, 50);
  liveliness_watch_note(&w, &s, 510);
  s = status(0, 1, -1, 1, 52);
  liveliness_watch_note(&w, &s, 520);
  CHECK(liveliness_watch_pop(&w, 1000, 20, &e));
  CHECK(e.writer == 50 && e.regained == 1);
  CHECK(liveliness_watch_pop(&w, 1000, 20, &e));
  CHECK(e.writer == 52 && e.regained == 0);
  /* Overflow keeps the newest entries and counts the dropped ones. */
  for (int i = 0; i < LIVELINESS_WATCH_CAP + 5; i++) {
    s = status(0, 1, -1, 1, (dds_instance_handle_t)(1000 + i));
    liveliness_watch_note(&w, &s, (uint64_t)i);
  }
  CHECK(w.dropped == 5);
  CHECK(liveliness_watch_pop(&w, 1000, 0, &e));
  CHECK(e.writer == 1005);
  int n = 1;
  while (liveliness_watch_pop(&w, 1000, 0, &e)) n++;
  CHECK(n == LIVELINESS_WATCH_CAP);
  CHECK(e.writer == 1000 + LIVELINESS_WATCH_CAP + 4);
  liveliness_watch_destroy(&w);
}

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
  dds_liveliness_changed_status_t st = status(1, 0, 1, 0, 7);
  feedback_slot_liveliness(&s, &st, 1000);
  CHECK(!feedback_slot_server_lost(&s, &lost_ns, &last));
  /* The server dies: the very next read renders no wall. */
  st = status(0, 1, -1, 1, 7);
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
  st = status(1, 0, 1, -1, 8);
  feedback_slot_liveliness(&s, &st, 40000000);
  CHECK(!feedback_slot_server_lost(&s, &lost_ns, &last));
  CHECK(s.regained_events == 1);
  s.model.in_contact = 1;
  st = status(1, 0, 1, 0, 9); /* a second writer joins: alive 2 */
  st.alive_count = 2;
  feedback_slot_liveliness(&s, &st, 41000000);
  st = status(1, 1, -1, 1, 8);
  feedback_slot_liveliness(&s, &st, 42000000);
  CHECK(!feedback_slot_server_lost(&s, &lost_ns, &last));
  feedback_slot_read(&s, &m);
  CHECK(m.in_contact == 1);
  feedback_slot_destroy(&s);
}

int main(void) {
  test_watch();
  test_slot();
  return check_report("test_liveliness");
}
