#include "seat.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "viscera.h"

int seat_open(seat_t *s, int domain, const char *partition, verr_t *err) {
  memset(s, 0, sizeof *s);
  snprintf(s->partition, sizeof s->partition, "%s", partition);
  if (scene_view_open(&s->sv, domain, partition, NULL, NULL, err)) return -1;
  s->rd_event = vdds_reader(&s->sv.dds, VT_SESSION_EVENT, err);
  if (s->rd_event < 0) {
    scene_view_close(&s->sv);
    return -1;
  }
  return 0;
}

void seat_close(seat_t *s) { scene_view_close(&s->sv); }

static void on_event(seat_t *s, const viscera_SessionEvent *e, double now) {
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
    break;
  }
  case viscera_EVENT_CLIENT_LOST:
    s->client_lost = 1;
    break;
  case viscera_EVENT_CONTACT_BEGIN:
    s->client_lost = 0;
    break;
  default:
    break;
  }
}

int seat_poll(seat_t *s, double now, verr_t *err) {
  if (scene_view_poll(&s->sv, err) < 0) return -1;
  for (;;) {
    void *samples[16] = {0};
    dds_sample_info_t infos[16];
    int n = dds_take(s->rd_event, samples, infos, 16, 16);
    if (n <= 0) break;
    for (int i = 0; i < n; i++)
      if (infos[i].valid_data) on_event(s, samples[i], now);
    dds_return_loan(s->rd_event, samples, n);
  }
  if (now > s->alert_until) s->alert = SEAT_OK;
  return 0;
}

double seat_force(const seat_t *s, float *st, float *mpf, float *sft, float *max_force) {
  int p = scene_view_primary_tool(&s->sv);
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

void seat_sample(seat_t *s) {
  float st, mpf, sft, mf;
  double f = seat_force(s, &st, &mpf, &sft, &mf);
  s->history[s->nhist++ % SEAT_HISTORY] = (float)f;
  if (f > s->peak) s->peak = (float)f;
}
