/* SPDX-License-Identifier: Apache-2.0 */
/* The dashboard's wording and colours (client/dashboard/seat_text.h): the
 * level of a force against the thresholds, who drives a tool from its
 * ToolRole, untrusted text cleaned, which events the focus view lists. */
#include <string.h>

#include "check.h"
#include "seat_text.h"
#include "viscera.h"

static void test_levels(void) {
  CHECK(seat_level_of(0.4, 0.5f, 0.8f, 1.5f) == SEAT_OK);
  CHECK(seat_level_of(0.5, 0.5f, 0.8f, 1.5f) == SEAT_ABOVE_ST); /* at a threshold counts as reached */
  CHECK(seat_level_of(0.97, 0.5f, 0.8f, 1.5f) == SEAT_ABOVE_MPF);
  CHECK(seat_level_of(2.0, 0.5f, 0.8f, 1.5f) == SEAT_ABOVE_SFT);
  /* Unset thresholds (0) are never reached; the set ones still are. */
  CHECK(seat_level_of(5.0, 0, 0, 0) == SEAT_OK);
  CHECK(seat_level_of(0.9, 0, 0.8f, 0) == SEAT_ABOVE_MPF);
  CHECK(seat_level_of(NAN, 0.5f, 0.8f, 1.5f) == SEAT_OK);
  CHECK(seat_level_of(INFINITY, 0.5f, 0.8f, 1.5f) == SEAT_OK);
  CHECK(strcmp(seat_level_name(SEAT_OK), "ok") == 0 && strcmp(seat_level_name(SEAT_ABOVE_MPF), "MPF") == 0);
  /* Distinct colours; above MPF reads red (red channel dominant). */
  double c[4][3];
  for (int a = 0; a < 4; a++) seat_level_rgb((seat_alert_t)a, c[a]);
  for (int a = 0; a < 4; a++)
    for (int b = a + 1; b < 4; b++)
      CHECK(fabs(c[a][0] - c[b][0]) + fabs(c[a][1] - c[b][1]) + fabs(c[a][2] - c[b][2]) > 0.3);
  CHECK(c[SEAT_ABOVE_MPF][0] > 0.8 && c[SEAT_ABOVE_MPF][1] < 0.3 && c[SEAT_ABOVE_MPF][2] < 0.3);
  CHECK(c[SEAT_OK][1] > c[SEAT_OK][0]); /* green below ST */
}

static void test_roles(void) {
  char b[160];
  CHECK(strcmp(seat_role_text(b, sizeof b, 0, "x", "y", 0.5), "any station") == 0); /* no ToolRole yet */
  CHECK(strcmp(seat_role_text(b, sizeof b, 1, "", "", 0), "any station") == 0);
  CHECK(strcmp(seat_role_text(b, sizeof b, 1, "alice", "", 0), "owner alice") == 0);
  CHECK(strcmp(seat_role_text(b, sizeof b, 1, "alice", "bob", 0.5f), "owner alice, guided by bob 50 %") == 0);
  CHECK(strcmp(seat_role_text(b, sizeof b, 1, "", "bob", 0.3f), "any station, guided by bob 30 %") == 0);
  CHECK(strcmp(seat_role_text(b, sizeof b, 1, "alice", "bob", 1.0f), "owner alice, taken over by bob") == 0);
  /* Wire text is untrusted: control characters do not reach the screen. */
  CHECK(strcmp(seat_role_text(b, sizeof b, 1, "al\nice\x1b", "", 0), "owner al?ice?") == 0);
  /* A short buffer truncates, never overflows. */
  char s[8];
  seat_role_text(s, sizeof s, 1, "alice", "bob", 0.5f);
  CHECK(strlen(s) == 7);
  char d[4];
  seat_text_clean(d, sizeof d, "abcdef");
  CHECK(strcmp(d, "abc") == 0);
  seat_text_clean(d, sizeof d, NULL);
  CHECK(d[0] == 0);
}

static void test_events(void) {
  CHECK(seat_event_label(viscera_EVENT_THRESHOLD_CROSSED_UP) != NULL);
  CHECK(strcmp(seat_event_label(viscera_EVENT_CLIENT_LOST), "client lost") == 0);
  CHECK(strcmp(seat_event_label(viscera_EVENT_CONTROL_APPLIED), "control") == 0);
  /* Noise the instructor does not need in a short list. */
  CHECK(seat_event_label(viscera_EVENT_CONTACT_BEGIN) == NULL);
  CHECK(seat_event_label(viscera_EVENT_KEYFRAME) == NULL);
  CHECK(seat_event_label(viscera_EVENT_TOPOLOGY_CHANGED) == NULL);
  CHECK(seat_event_label(-1) == NULL && seat_event_label(1000) == NULL);
}

int main(void) {
  test_levels();
  test_roles();
  test_events();
  return check_report("test_seat_text");
}
