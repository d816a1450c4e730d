/* SPDX-License-Identifier: Apache-2.0 */
#include "feedback_slot.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "viscera.h"
#include "vmath.h"
#include "vtime.h"

/* vdds_gate_check_fn: this tool's samples only (reason 1). */
static int own_tool_check(const void *sample, void *arg) {
  return ((const viscera_ContactFeedback *)sample)->tool_id == ((const feedback_slot_t *)arg)->tool_id ? 0 : 1;
}

int feedback_slot_init(feedback_slot_t *s, uint32_t tool_id, size_t latency_capacity) {
  memset(s, 0, sizeof *s);
  s->tool_id = tool_id;
  vdds_gate_init(&s->gate, tool_id + 1, own_tool_check, s);
  s->cap = latency_capacity;
  s->latency_us = malloc((latency_capacity + 1) * sizeof(double));
  if (!s->latency_us) return -1;
  for (size_t i = 0; i < FEEDBACK_SENT_RING; i++) atomic_init(&s->sent_mono_ns[i], 0);
  pthread_mutex_init(&s->lock, NULL);
  return 0;
}

void feedback_slot_destroy(feedback_slot_t *s) {
  pthread_mutex_destroy(&s->lock);
  vdds_gate_destroy(&s->gate);
  free(s->latency_us);
  s->latency_us = NULL;
}

void feedback_slot_sent(feedback_slot_t *s, uint64_t seq, uint64_t client_mono_ns) {
  feedback_slot_sent_at(s, seq, client_mono_ns, NULL);
}

void feedback_slot_sent_at(feedback_slot_t *s, uint64_t seq, uint64_t client_mono_ns, const double pos[3]) {
  size_t i = seq % FEEDBACK_SENT_RING;
  /* The tip first, then the time that publishes it (release): a reader that
   * sees this time sees this tip. */
  for (int k = 0; k < 3; k++)
    atomic_store_explicit(&s->sent_pos[i][k], pos ? (float)pos[k] : NAN, memory_order_relaxed);
  atomic_store_explicit(&s->sent_mono_ns[i], client_mono_ns, memory_order_release);
}

void feedback_slot_set_reach(feedback_slot_t *s, float max_reach) {
  pthread_mutex_lock(&s->lock);
  s->max_reach = max_reach > 0 && isfinite(max_reach) ? max_reach : 0;
  pthread_mutex_unlock(&s->lock);
}

/* The proxy of an echo of our command `seq` against the tip we sent with
 * it: 1 when within reach (or either is unknown). */
static int within_reach(const feedback_slot_t *s, const viscera_ContactFeedback *fb) {
  if (!(s->max_reach > 0)) return 1;
  size_t i = fb->cmd_seq % FEEDBACK_SENT_RING;
  double d2 = 0;
  for (int k = 0; k < 3; k++) {
    double p = atomic_load_explicit(&s->sent_pos[i][k], memory_order_relaxed);
    if (!isfinite(p)) return 1;
    d2 += (fb->proxy_position[k] - p) * (fb->proxy_position[k] - p);
  }
  return sqrt(d2) <= s->max_reach * 1.001 + 1e-6;
}

void feedback_slot_set_limits(feedback_slot_t *s, float max_stiffness, float max_force) {
  pthread_mutex_lock(&s->lock);
  s->max_stiffness = max_stiffness > 0 && isfinite(max_stiffness) ? max_stiffness : 0;
  s->max_force = max_force > 0 && isfinite(max_force) ? max_force : 0;
  pthread_mutex_unlock(&s->lock);
}

/* Within what the scene gives the tool (a float rounding's margin): a
 * stiffer plane or a larger force than the server can mean is a forgery. */
static int within_limits(const feedback_slot_t *s, const viscera_ContactFeedback *fb) {
  if (s->max_stiffness > 0 && fb->stiffness > s->max_stiffness * 1.001f) return 0;
  double f2 = 0;
  for (int k = 0; k < 3; k++) f2 += (double)fb->force[k] * fb->force[k];
  return !(s->max_force > 0 && sqrt(f2) > s->max_force * 1.001);
}

int feedback_slot_accept(feedback_slot_t *s, const viscera_ContactFeedback *fb, uint64_t now) {
  return feedback_slot_accept_from(s, fb, 0, now);
}

int feedback_slot_accept_from(feedback_slot_t *s, const viscera_ContactFeedback *fb, dds_instance_handle_t writer,
                              uint64_t now) {
  if (fb->tool_id != s->tool_id) return 0;
  /* Untrusted: never render a plane built from NaN or a negative stiffness. */
  int ok = isfinite(fb->stiffness) && fb->stiffness >= 0;
  for (int k = 0; k < 3; k++)
    ok = ok && isfinite(fb->proxy_position[k]) && isfinite(fb->normal[k]) && isfinite(fb->force[k]);
  /* Our own command's echo (seq and send time as we sent them), or another
   * station's sharing the tool: only ours is a round trip of ours. */
  int ours = fb->cmd_client_mono_ns > 0 && atomic_load_explicit(&s->sent_mono_ns[fb->cmd_seq % FEEDBACK_SENT_RING],
                                                                memory_order_acquire) == fb->cmd_client_mono_ns;
  pthread_mutex_lock(&s->lock);
  if (ok && (!within_limits(s, fb) || (ours && !within_reach(s, fb)))) {
    s->out_of_limits++;
    ok = 0;
  }
  if (!ok) {
    s->rejected++;
    pthread_mutex_unlock(&s->lock);
    return -1;
  }
  if (writer) { /* newest wins per writer: best effort may deliver out of order */
    if (writer == s->last_writer && fb->seq <= s->last_seq) {
      s->stale++;
      pthread_mutex_unlock(&s->lock);
      return -2;
    }
    s->last_writer = writer;
    s->last_seq = fb->seq;
  }
  s->model.in_contact = fb->in_contact;
  s->model.stiffness = fb->stiffness;
  s->model.cmd_seq = ours ? fb->cmd_seq : 0; /* another station's seq says nothing of our hand */
  for (int k = 0; k < 3; k++) {
    s->model.proxy[k] = fb->proxy_position[k];
    s->model.normal[k] = fb->normal[k];
  }
  v3_normalize(s->model.normal);
  s->arrival_mono_ns = now;
  s->received++;
  if (!ours && fb->cmd_client_mono_ns > 0) s->foreign_echoes++;
  if (ours && fb->cmd_seq != s->last_cmd_seq && fb->cmd_client_mono_ns <= now) {
    s->last_cmd_seq = fb->cmd_seq;
    if (s->nlatency < s->cap) s->latency_us[s->nlatency++] = (double)(now - fb->cmd_client_mono_ns) * 1e-3;
  }
  pthread_mutex_unlock(&s->lock);
  return 1;
}

/* The seat's server's samples only (seat_server.h); a writer that can
 * never be the server is blocked at the gate. */
static int from_server(feedback_slot_t *s, dds_entity_t reader, dds_instance_handle_t pub) {
  if (!s->server) return 1;
  seat_verdict_t v = seat_server_from(s->server, reader, pub);
  if (v == SEAT_FROM_SERVER) return 1;
  if (v == SEAT_NOT_SERVER) vdds_gate_block(&s->gate, pub, VDDS_GATE_ANY_KEY);
  pthread_mutex_lock(&s->lock);
  s->ignored++;
  pthread_mutex_unlock(&s->lock);
  return 0;
}

static void on_data(dds_entity_t reader, void *arg) {
  feedback_slot_t *s = arg;
  void *samples[8] = {0};
  dds_sample_info_t infos[8];
  int n = dds_take(reader, samples, infos, 8, 8);
  uint64_t now = vtime_mono_ns();
  seat_limits_t lim;
  if (n > 0 && s->server && seat_server_limits(s->server, &lim) && s->tool_id < lim.ntools) {
    feedback_slot_set_limits(s, lim.tool_stiffness[s->tool_id], lim.tool_max_force[s->tool_id]);
    feedback_slot_set_reach(s, lim.tool_reach[s->tool_id]);
  }
  for (int i = 0; i < n; i++)
    if (infos[i].valid_data && from_server(s, reader, infos[i].publication_handle))
      feedback_slot_accept_from(s, samples[i], infos[i].publication_handle, now);
  if (n > 0) dds_return_loan(reader, samples, n);
}

void feedback_slot_liveliness(feedback_slot_t *s, const dds_liveliness_changed_status_t *st, uint64_t now) {
  pthread_mutex_lock(&s->lock);
  int32_t alive = (int32_t)st->alive_count - s->nonserver_alive;
  s->writers_alive = alive > 0 ? (uint32_t)alive : 0;
  if (s->writers_alive == 0 && st->alive_count_change < 0 && !s->server_lost) {
    /* The server is gone: stop rendering its wall now rather than after the
     * feedback timeout. */
    s->model.in_contact = 0;
    s->server_lost = 1;
    s->lost_mono_ns = now;
    s->lost_last_arrival = s->arrival_mono_ns;
    s->lost_events++;
  } else if (s->writers_alive > 0 && s->server_lost) {
    s->server_lost = 0;
    s->regained_events++;
  }
  pthread_mutex_unlock(&s->lock);
}

static void on_liveliness(dds_entity_t reader, const dds_liveliness_changed_status_t status, void *arg) {
  feedback_slot_t *s = arg;
  /* A writer that is not the server (an impostor's) neither keeps the
   * server alive nor loses it: its changes are set apart. */
  if (s->server && status.last_publication_handle &&
      seat_server_from(s->server, reader, status.last_publication_handle) == SEAT_NOT_SERVER) {
    pthread_mutex_lock(&s->lock);
    s->nonserver_alive += status.alive_count_change;
    pthread_mutex_unlock(&s->lock);
    return;
  }
  feedback_slot_liveliness(s, &status, vtime_mono_ns());
}

int feedback_slot_server_lost(feedback_slot_t *s, uint64_t *lost_ns, uint64_t *last_arrival) {
  pthread_mutex_lock(&s->lock);
  int lost = s->server_lost;
  *lost_ns = s->lost_mono_ns;
  *last_arrival = s->lost_last_arrival;
  pthread_mutex_unlock(&s->lock);
  return lost;
}

dds_entity_t feedback_slot_attach(feedback_slot_t *s, vdds_t *v, verr_t *err) {
  dds_listener_t *l = dds_create_listener(s);
  dds_lset_data_available(l, on_data);
  dds_lset_liveliness_changed(l, on_liveliness);
  /* Gated (dds/vdds_gate.h): one instance, this tool's, and no writer once
   * judged never to be the server. */
  dds_entity_t r = vdds_reader_gated(v, VT_CONTACT_FEEDBACK, &s->gate, 0, 1, l, err);
  dds_delete_listener(l);
  return r;
}

uint64_t feedback_slot_read(feedback_slot_t *s, contact_model_t *out) {
  pthread_mutex_lock(&s->lock);
  *out = s->model;
  uint64_t t = s->arrival_mono_ns;
  pthread_mutex_unlock(&s->lock);
  return t;
}
