/* SPDX-License-Identifier: Apache-2.0 */
/* Loss detection bookkeeping of the server: the liveliness watch (which
 * writers to release), fed with the status values Cyclone's
 * liveliness-changed listener delivers (the haptic client's side is
 * tests/client/haptic/test_feedback_slot.c). The DDS path itself is covered
 * by the `liveliness` integration test. */
#include <string.h>

#include "check.h"
#include "session/liveliness_watch.h"
#include "test_dds.h"

static void test_watch(void) {
  liveliness_watch_t w;
  liveliness_watch_init(&w);
  liveliness_lost_t e;
  CHECK(!liveliness_watch_pop(&w, 1000, 0, &e));
  /* A writer appears: nothing to release. */
  dds_liveliness_changed_status_t s = test_liveliness_status(1, 0, 1, 0, 42);
  liveliness_watch_note(&w, &s, 100);
  CHECK(!liveliness_watch_pop(&w, 1000, 0, &e));
  CHECK(w.regained_total == 1);
  /* Its lease expires: alive -> not alive. */
  s = test_liveliness_status(0, 1, -1, 1, 42);
  liveliness_watch_note(&w, &s, 200);
  /* Another writer is deleted while alive (clean exit). */
  s = test_liveliness_status(0, 1, -1, 0, 43);
  liveliness_watch_note(&w, &s, 300);
  /* A not-alive writer is later removed altogether: not a new loss. */
  s = test_liveliness_status(0, 0, 0, -1, 42);
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
  s = test_liveliness_status(0, 1, -1, 1, 50);
  liveliness_watch_note(&w, &s, 500);
  s = test_liveliness_status(1, 1, 1, 0, 51);
  liveliness_watch_note(&w, &s, 505);
  s = test_liveliness_status(1, 0, 1, -1, 50);
  liveliness_watch_note(&w, &s, 510);
  s = test_liveliness_status(0, 1, -1, 1, 52);
  liveliness_watch_note(&w, &s, 520);
  CHECK(liveliness_watch_pop(&w, 1000, 20, &e));
  CHECK(e.writer == 50 && e.regained == 1);
  CHECK(liveliness_watch_pop(&w, 1000, 20, &e));
  CHECK(e.writer == 52 && e.regained == 0);
  /* Overflow keeps the newest entries and counts the dropped ones. */
  for (int i = 0; i < LIVELINESS_WATCH_CAP + 5; i++) {
    s = test_liveliness_status(0, 1, -1, 1, (dds_instance_handle_t)(1000 + i));
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

int main(void) {
  test_watch();
  return check_report("test_liveliness_watch");
}
