/* SPDX-License-Identifier: Apache-2.0 */
#include "seat.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "viscera.h"

int seat_open(seat_t *s, int domain, const char *partition, verr_t *err) {
  memset(s, 0, sizeof *s);
  snprintf(s->partition, sizeof s->partition, "%s", partition);
  if (scene_view_open(&s->sv, domain, partition, NULL, NULL, err)) return -1;
  /* Keys bounded (issue 15.1): the server's events are source 0, tools
   * below viscera_MAX_TOOLS. */
  vdds_gate_init(&s->gate_event, 1, NULL, NULL);
  vdds_gate_init(&s->gate_role, viscera_MAX_TOOLS, NULL, NULL);
  vdds_gate_init(&s->gate_measures, viscera_MAX_TOOLS, NULL, NULL);
  s->rd_event = vdds_reader_gated(&s->sv.dds, VT_SESSION_EVENT, &s->gate_event, 0, 1, NULL, err);
  if (s->rd_event >= 0)
    s->rd_role = vdds_reader_gated(&s->sv.dds, VT_TOOL_ROLE, &s->gate_role, 0, viscera_MAX_TOOLS, NULL, err);
  if (s->rd_event >= 0 && s->rd_role >= 0)
    s->rd_measures = vdds_reader_gated(&s->sv.dds, VT_TOOL_METRICS, &s->gate_measures, 0, viscera_MAX_TOOLS, NULL, err);
  if (s->rd_measures >= 0) s->rd_presence = vdds_reader(&s->sv.dds, VT_TOOL_COMMAND, err);
  if (s->rd_event < 0 || s->rd_role < 0 || s->rd_measures < 0 || s->rd_presence < 0) {
    scene_view_close(&s->sv);
    return -1;
  }
  return 0;
}

void seat_close(seat_t *s) {
  scene_view_close(&s->sv);
  vdds_gate_destroy(&s->gate_event);
  vdds_gate_destroy(&s->gate_role);
  vdds_gate_destroy(&s->gate_measures);
}

static void keep_event(seat_t *s, const viscera_SessionEvent *e) {
  if (!seat_event_label((int)e->kind)) return;
  seat_event_t *k = &s->events[s->nevents++ % SEAT_EVENTS];
  k->sim_s = (double)e->sim_time_ns * 1e-9;
  k->kind = (int)e->kind;
  seat_text_clean(k->text, sizeof k->text, e->text);
}

const seat_event_t *seat_event(const seat_t *s, unsigned k) {
  uint64_t kept = s->nevents < SEAT_EVENTS ? s->nevents : SEAT_EVENTS;
  return k < kept ? &s->events[(s->nevents - 1 - k) % SEAT_EVENTS] : NULL;
}

/* Sample handlers: x is the reader's sample type. */
static void on_role(seat_t *s, const void *x, double now) {
  const viscera_ToolRole *r = x;
  (void)now;
  if (r->tool_id >= SCENE_VIEW_MAX_TOOLS || !isfinite(r->authority) || r->authority < 0 || r->authority > 1) {
    s->rejected++;
    return;
  }
  seat_role_t *d = &s->roles[r->tool_id];
  seat_role_t nr = {.have = 1, .changed = 1, .authority = r->authority};
  snprintf(nr.owner, sizeof nr.owner, "%s", r->owner);
  snprintf(nr.guide, sizeof nr.guide, "%s", r->guide);
  if (!d->have || strcmp(d->owner, nr.owner) || strcmp(d->guide, nr.guide) || d->authority != nr.authority) *d = nr;
}

static void on_measures(seat_t *s, const void *x, double now) {
  const viscera_ToolMetrics *m = x;
  (void)now;
  const double v[4] = {m->peak_force, m->time_above_st, m->time_above_mpf, m->time_above_sft};
  int ok = m->tool_id < SCENE_VIEW_MAX_TOOLS;
  for (int i = 0; i < 4 && ok; i++) ok = isfinite(v[i]) && v[i] >= 0;
  if (!ok) {
    s->rejected++;
    return;
  }
  seat_tool_measures_t *d = &s->measures[m->tool_id];
  d->have = 1;
  d->peak = v[0];
  for (int i = 0; i < 3; i++) d->above[i] = v[i + 1];
}

/* Takes every sample of reader rd and hands each valid one of the seat's
 * server to fn (seat_server.h, learnt by the scene view); the rest are
 * counted in the view's `ignored` and their writers blocked at gate g.
 * Until the server is known the samples wait in the reader. */
static void take_all(seat_t *s, dds_entity_t rd, vdds_gate_t *g, void (*fn)(seat_t *, const void *, double),
                     double now) {
  if (!s->sv.server.known) return;
  for (;;) {
    void *samples[16] = {0};
    dds_sample_info_t infos[16];
    int n = dds_take(rd, samples, infos, 16, 16);
    if (n <= 0) break;
    for (int i = 0; i < n; i++) {
      if (!infos[i].valid_data) continue;
      seat_verdict_t v = seat_server_from(&s->sv.server, rd, infos[i].publication_handle);
      if (v == SEAT_FROM_SERVER) {
        fn(s, samples[i], now);
        continue;
      }
      if (v == SEAT_NOT_SERVER) vdds_gate_block(g, infos[i].publication_handle, VDDS_GATE_ANY_KEY);
      s->sv.ignored++;
    }
    dds_return_loan(rd, samples, n);
  }
}

/* Which server of the seat is adopted now (+1 per restart, seat_server.h). */
static uint32_t server_generation(seat_t *s) {
  pthread_mutex_lock(&s->sv.server.lock);
  uint32_t g = s->sv.server.generation;
  pthread_mutex_unlock(&s->sv.server.lock);
  return g;
}

static void on_event(seat_t *s, const void *x, double now) {
  const viscera_SessionEvent *e = x;
  keep_event(s, e);
  switch (e->kind) {
  case viscera_EVENT_THRESHOLD_CROSSED_UP: {
    /* Which level: the event's text starts with its name (server.c). */
    seat_alert_t a = strncmp(e->text, "SFT", 3) == 0   ? SEAT_ABOVE_SFT
                     : strncmp(e->text, "MPF", 3) == 0 ? SEAT_ABOVE_MPF
                     : strncmp(e->text, "ST", 2) == 0  ? SEAT_ABOVE_ST
                                                       : SEAT_OK;
    if (a == SEAT_OK) return;
    s->crossings[a - 1]++;
    if (a >= s->alert || now > s->alert_until) s->alert = a;
    s->alert_until = now + SEAT_ALERT_HOLD_S;
    s->alert_sim_s = (double)e->sim_time_ns * 1e-9;
    break;
  }
  case viscera_EVENT_CLIENT_LOST:
    /* The server says "left" for a deleted writer; a dispose already seen
     * means the same. */
    if (strstr(e->text, "client left"))
      s->client_left = 1, s->client_lost = 0;
    else if (!s->client_left)
      s->client_lost = 1;
    break;
  case viscera_EVENT_CONTACT_BEGIN:
    s->client_lost = s->client_left = 0;
    break;
  case viscera_EVENT_CONTROL_APPLIED:
    /* The server's answer carries the command's kind in `value`; a reset
     * keeps the pause (the server does), so only these two change it. A
     * dashboard started later takes the answer from the event history. */
    if (e->value == (double)viscera_CONTROL_PAUSE) {
      s->paused = 1;
      s->paused_gen = server_generation(s);
    } else if (e->value == (double)viscera_CONTROL_RESUME) {
      s->paused = 0;
    }
    break;
  default:
    break;
  }
}

/* The trainee's ToolCommand writers: present, left or lost (seat.h). A new
 * command clears both; then the reader's liveliness status since the last
 * poll: a writer deleted while alive (alive count down, no not-alive rise)
 * left; a lease that expired (not-alive count up) was lost. The samples
 * themselves are dropped. */
static void seat_presence(seat_t *s) {
  for (;;) {
    void *samples[16] = {0};
    dds_sample_info_t infos[16];
    int n = dds_take(s->rd_presence, samples, infos, 16, 16);
    if (n <= 0) break;
    for (int i = 0; i < n; i++)
      if (infos[i].valid_data) s->client_left = s->client_lost = 0;
    dds_return_loan(s->rd_presence, samples, n);
  }
  dds_liveliness_changed_status_t st;
  if (dds_get_liveliness_changed_status(s->rd_presence, &st) != DDS_RETCODE_OK) return;
  if (st.not_alive_count_change > 0 && !s->client_left)
    s->client_lost = 1;
  else if (st.alive_count_change < 0 && st.not_alive_count_change <= 0)
    s->client_left = 1, s->client_lost = 0;
}

int seat_poll(seat_t *s, double now, verr_t *err) {
  if (scene_view_poll(&s->sv, err) < 0) return -1;
  seat_presence(s);
  take_all(s, s->rd_event, &s->gate_event, on_event, now);
  take_all(s, s->rd_role, &s->gate_role, on_role, now);
  take_all(s, s->rd_measures, &s->gate_measures, on_measures, now);
  if (now > s->alert_until) s->alert = SEAT_OK;
  /* A restarted server starts unpaused; its history holds no resume. */
  if (s->paused && server_generation(s) != s->paused_gen) s->paused = 0;
  /* A dashboard started late takes the seat's past events (SessionEvent is
   * transient-local): a crossing long over in the seat's simulated time
   * raises no alert. (After a reset the simulated time restarts below the
   * crossing's; the dashboard's own hold then ends the alert.) */
  double sim_now = (double)scene_view_sim_time_ns(&s->sv) * 1e-9;
  if (s->alert != SEAT_OK && sim_now - s->alert_sim_s > SEAT_ALERT_HOLD_S) {
    s->alert = SEAT_OK;
    s->alert_until = 0;
  }
  /* A trainee still pressing above a threshold stays alerted after the
   * crossing's hold runs out. */
  float st, mpf, sft, mf;
  double f = seat_force(s, &st, &mpf, &sft, &mf); /* before reading the thresholds it sets */
  seat_alert_t cur = seat_level_of(f, st, mpf, sft);
  if (cur > s->alert) s->alert = cur;
  return 0;
}

int seat_tool(const seat_t *s) {
  int p = scene_view_primary_tool(&s->sv);
  for (int i = 0; p < 0 && i < SCENE_VIEW_MAX_TOOLS; i++)
    if (s->sv.tools[i].listed) p = i;
  return p;
}

double seat_force(const seat_t *s, float *st, float *mpf, float *sft, float *max_force) {
  int p = seat_tool(s);
  *st = *mpf = *sft = 0;
  *max_force = SCENE_VIEW_TOOL_MAX_FORCE;
  if (p < 0) return 0;
  const sv_tool_t *t = &s->sv.tools[p];
  *st = t->st, *mpf = t->mpf, *sft = t->sft, *max_force = t->max_force;
  if (!t->have_contact || !t->in_contact) return 0;
  double f =
      sqrt((double)t->force[0] * t->force[0] + (double)t->force[1] * t->force[1] + (double)t->force[2] * t->force[2]);
  return isfinite(f) ? f : 0;
}

void seat_sample(seat_t *s, double dt) {
  float st, mpf, sft, mf;
  double f = seat_force(s, &st, &mpf, &sft, &mf);
  s->history[s->nhist++ % SEAT_HISTORY] = (float)f;
  if (f > s->peak) s->peak = (float)f;
  seat_alert_t lv = seat_level_of(f, st, mpf, sft);
  if (dt > 0 && dt < 1.0)
    for (int k = 0; k < (int)lv; k++) s->above_seen[k] += dt;
}
