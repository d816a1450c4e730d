/* SPDX-License-Identifier: Apache-2.0 */
/* bad_commands: an adversarial haptic client. Against a running server it
 * sends ToolCommands with NaN, Inf, absurd positions, bad quaternions, bad
 * ids and bad force capabilities, then a valid push into the organ. Exits 0
 * only if the server stayed alive, answered the valid push with a contact
 * force, never reported contact for a bad command, and published an
 * INPUT_REJECTED SessionEvent. Every bad command aims 1 cm inside the organ.
 * usage: bad_commands DOMAIN PARTITION */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "dds/vdds.h"
#include "viscera.h"
#include "vtime.h"

static int take_keyframe_top(dds_entity_t r, double top[3]) {
  void *s[1] = {0};
  dds_sample_info_t info;
  for (int tries = 0; tries < 500; tries++) {
    int n = dds_take(r, s, &info, 1, 1);
    if (n > 0) {
      const viscera_MeshState *m = s[0];
      int ok = 0;
      if (info.valid_data && m->positions._length >= 3) {
        /* The highest vertex: the probe comes down onto it from above. */
        top[2] = -INFINITY;
        for (uint32_t i = 0; i + 2 < m->positions._length; i += 3)
          if (m->positions._buffer[i + 2] > top[2])
            for (int k = 0; k < 3; k++) top[k] = m->positions._buffer[i + k];
        ok = 1;
      }
      dds_return_loan(r, s, n);
      if (ok) return 0;
    }
    dds_sleepfor(DDS_MSECS(10));
  }
  return -1;
}

static void send(dds_entity_t w, uint32_t tool, const float pos[3], const float q[4], float max_force, uint64_t *seq) {
  viscera_ToolCommand c;
  memset(&c, 0, sizeof c);
  c.tool_id = tool;
  c.seq = ++*seq;
  c.client_mono_ns = vtime_mono_ns();
  memcpy(c.position, pos, sizeof c.position);
  memcpy(c.orientation, q, sizeof c.orientation);
  c.max_force = max_force;
  dds_write(w, &c);
}

/* Max contact force seen over `ms` milliseconds of feedback; *any_feedback
 * is set by any sample (the server answers only tools it has accepted a
 * command for), *any_contact by a sample in contact. */
static double watch_force(dds_entity_t r, int ms, int *any_feedback, int *any_contact) {
  double peak = 0;
  uint64_t until = vtime_mono_ns() + (uint64_t)ms * 1000000ull;
  while (vtime_mono_ns() < until) {
    void *s[4] = {0};
    dds_sample_info_t info[4];
    int n = dds_take(r, s, info, 4, 4);
    for (int i = 0; i < n; i++) {
      const viscera_ContactFeedback *fb = s[i];
      if (!info[i].valid_data) continue;
      double f = sqrt((double)fb->force[0] * fb->force[0] + (double)fb->force[1] * fb->force[1] +
                      (double)fb->force[2] * fb->force[2]);
      *any_feedback = 1;
      if (fb->in_contact) *any_contact = 1;
      if (f > peak) peak = f;
    }
    if (n > 0) dds_return_loan(r, s, n);
    dds_sleepfor(DDS_MSECS(1));
  }
  return peak;
}

int main(int argc, char **argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: bad_commands DOMAIN PARTITION\n");
    return 2;
  }
  vdds_t v;
  verr_t err;
  if (vdds_open(&v, cli_parse_domain(argv[1]), argv[2], &err)) {
    fprintf(stderr, "bad_commands: %s\n", err.msg);
    return 1;
  }
  dds_entity_t w = vdds_writer(&v, VT_TOOL_COMMAND, &err);
  dds_entity_t r_fb = vdds_reader(&v, VT_CONTACT_FEEDBACK, &err);
  dds_entity_t r_state = vdds_reader(&v, VT_MESH_STATE, &err);
  dds_entity_t r_ev = vdds_reader(&v, VT_SESSION_EVENT, &err);
  double top[3];
  if (take_keyframe_top(r_state, top)) {
    fprintf(stderr, "bad_commands: no keyframe from the server within 5 s\n");
    return 1;
  }
  printf("organ top at %.4f %.4f %.4f\n", top[0], top[1], top[2]);
  const float unit[4] = {1, 0, 0, 0};
  float inside[3] = {(float)top[0], (float)top[1], (float)(top[2] - 0.01)};
  float above[3] = {(float)top[0], (float)top[1], (float)(top[2] + 0.03)};
  uint64_t seq = 0;
  /* Bad commands. Had the server accepted any, it would answer with feedback. */
  int feedback_from_bad = 0, dummy = 0;
  /* One per 2 ms: ToolCommand is keep-last 1 per tool, so a burst would
   * leave the server only the last of it. */
  for (int round = 0; round < 30; round++) {
    float nanpos[3] = {NAN, inside[1], inside[2]};
    float infpos[3] = {inside[0], INFINITY, inside[2]};
    float absurd[3] = {inside[0], inside[1], 1e9f};
    float badq[4] = {3, 0, 0, 0};
    float nanq[4] = {NAN, 0, 0, 0};
    for (int kind = 0; kind < 9; kind++) {
      switch (kind) {
      case 0:
        send(w, 0, nanpos, unit, 4, &seq);
        break;
      case 1:
        send(w, 0, infpos, unit, 4, &seq);
        break;
      case 2:
        send(w, 0, absurd, unit, 4, &seq);
        break;
      case 3:
        send(w, 0, inside, badq, 4, &seq);
        break;
      case 4:
        send(w, 0, inside, nanq, 4, &seq);
        break;
      case 5:
        send(w, 0, inside, unit, NAN, &seq);
        break;
      case 6:
        send(w, 0, inside, unit, -5, &seq);
        break;
      case 7:
        send(w, 7, inside, unit, 4, &seq);
        break;
      default:
        send(w, 0xffffffffu, inside, unit, 4, &seq);
        break;
      }
      watch_force(r_fb, 2, &feedback_from_bad, &dummy);
    }
  }
  watch_force(r_fb, 100, &feedback_from_bad, &dummy);
  /* A valid push: approach from above, then go 1 cm inside. */
  int contact = 0, fb = 0;
  for (int i = 0; i < 300; i++) {
    float p[3];
    double a = i < 100 ? 0 : (i - 100) / 200.0;
    for (int k = 0; k < 3; k++) p[k] = (float)(above[k] + a * (inside[k] - above[k]));
    send(w, 0, p, unit, 4, &seq);
    dds_sleepfor(DDS_MSECS(1));
  }
  double peak = 0;
  for (int i = 0; i < 200; i++) {
    send(w, 0, inside, unit, 4, &seq);
    peak = fmax(peak, watch_force(r_fb, 1, &fb, &contact));
  }
  /* The rejection must have been reported as a SessionEvent. */
  int rejected_event = 0;
  void *s[64] = {0};
  dds_sample_info_t info[64];
  int n = dds_take(r_ev, s, info, 64, 64);
  for (int i = 0; i < n; i++)
    if (info[i].valid_data && ((viscera_SessionEvent *)s[i])->kind == viscera_EVENT_INPUT_REJECTED) rejected_event = 1;
  if (n > 0) dds_return_loan(r_ev, s, n);
  printf("feedback_from_bad=%d valid_contact=%d peak_force=%.3f rejected_event=%d\n", feedback_from_bad, contact, peak,
         rejected_event);
  vdds_close(&v);
  return (!feedback_from_bad && contact && peak > 0.1 && rejected_event) ? 0 : 1;
}
