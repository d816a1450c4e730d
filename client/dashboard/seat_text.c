/* SPDX-License-Identifier: Apache-2.0 */
#include "seat_text.h"

#include <math.h>
#include <stdio.h>

#include "viscera.h"

seat_alert_t seat_level_of(double f, float st, float mpf, float sft) {
  if (!isfinite(f)) return SEAT_OK;
  if (sft > 0 && f >= sft) return SEAT_ABOVE_SFT;
  if (mpf > 0 && f >= mpf) return SEAT_ABOVE_MPF;
  if (st > 0 && f >= st) return SEAT_ABOVE_ST;
  return SEAT_OK;
}

const char *seat_level_name(seat_alert_t a) {
  static const char *const n[] = {"ok", "ST", "MPF", "SFT"};
  return a >= SEAT_OK && a <= SEAT_ABOVE_SFT ? n[a] : "?";
}

void seat_level_rgb(seat_alert_t a, double rgb[3]) {
  /* Traffic-light order, with magenta past red for the hard stop: amber and
   * red are what an instructor already reads as "careful" and "too much". */
  static const double c[4][3] = {{0.25, 0.72, 0.35}, {0.95, 0.6, 0.1}, {0.9, 0.2, 0.2}, {0.85, 0.2, 0.75}};
  int i = a >= SEAT_OK && a <= SEAT_ABOVE_SFT ? (int)a : 0;
  for (int k = 0; k < 3; k++) rgb[k] = c[i][k];
}

void seat_text_clean(char *dst, size_t n, const char *src) {
  size_t i = 0;
  for (; src && src[i] && i + 1 < n; i++) dst[i] = src[i] >= 0x20 && src[i] < 0x7f ? src[i] : '?';
  dst[i] = 0;
}

char *seat_role_text(char *buf, size_t n, int have, const char *owner, const char *guide, double authority) {
  char o[40], g[40];
  seat_text_clean(o, sizeof o, have ? owner : "");
  seat_text_clean(g, sizeof g, have ? guide : "");
  char who[64];
  if (o[0])
    snprintf(who, sizeof who, "owner %s", o);
  else
    snprintf(who, sizeof who, "any station");
  if (!g[0])
    snprintf(buf, n, "%s", who);
  else if (isfinite(authority) && authority >= 1.0)
    snprintf(buf, n, "%s, taken over by %s", who, g);
  else
    snprintf(buf, n, "%s, guided by %s %.0f %%", who, g, isfinite(authority) ? fmax(0.0, authority) * 100.0 : 0.0);
  return buf;
}

const char *seat_event_label(int kind) {
  switch (kind) {
  case viscera_EVENT_SESSION_STARTED:
    return "started";
  case viscera_EVENT_SESSION_STOPPED:
    return "stopped";
  case viscera_EVENT_INPUT_REJECTED:
    return "rejected";
  case viscera_EVENT_STEP_ROLLED_BACK:
    return "rolled back";
  case viscera_EVENT_CLIENT_LOST:
    return "client lost";
  case viscera_EVENT_THRESHOLD_CROSSED_UP:
    return "crossed up";
  case viscera_EVENT_THRESHOLD_CROSSED_DOWN:
    return "back below";
  case viscera_EVENT_GRASP_BEGIN:
    return "grasp";
  case viscera_EVENT_GRASP_END:
    return "released";
  case viscera_EVENT_TASK_STARTED:
    return "task started";
  case viscera_EVENT_TASK_COMPLETED:
    return "task done";
  case viscera_EVENT_CONTROL_APPLIED:
    return "control";
  case viscera_EVENT_CUT_BEGIN:
    return "cut";
  case viscera_EVENT_CUT_END:
    return "cut ended";
  default:
    return NULL;
  }
}
