/* SPDX-License-Identifier: Apache-2.0 */
#include "training/thresholds.h"

#include <math.h>
#include <string.h>

const char *thr_name(thr_id_t which) {
  static const char *const n[THR_COUNT] = {[THR_ST] = "ST", [THR_MPF] = "MPF", [THR_SFT] = "SFT"};
  return (unsigned)which < THR_COUNT ? n[which] : "?";
}

const char *thr_long_name(thr_id_t which) {
  static const char *const n[THR_COUNT] = {
      [THR_ST] = "sound threshold", [THR_MPF] = "maximum palpation force", [THR_SFT] = "stopping force threshold"};
  return (unsigned)which < THR_COUNT ? n[which] : "?";
}

void thr_init(thr_tracker_t *t, double st, double mpf, double sft) {
  memset(t, 0, sizeof *t);
  t->level[THR_ST] = st > 0 ? st : 0;
  t->level[THR_MPF] = mpf > 0 ? mpf : 0;
  t->level[THR_SFT] = sft > 0 ? sft : 0;
}

static double hyst(double level) { return fmax(THR_HYST_MIN_N, THR_HYST_FRACTION * level); }

int thr_update(thr_tracker_t *t, double dt, double force, int in_contact, const double pos[3],
               thr_event_t ev[THR_COUNT]) {
  int n = 0;
  if (!isfinite(force) || force < 0) force = 0;
  if (force > t->peak_force) t->peak_force = force;
  /* Upward crossings low to high, downward high to low, so a jump across
   * several levels reads in the order a gradual change would produce. */
  for (int k = 0; k < THR_COUNT; k++) {
    double L = t->level[k];
    if (L > 0 && !t->above[k] && force > L) {
      t->above[k] = 1;
      t->crossings[k]++;
      ev[n++] = (thr_event_t){(thr_id_t)k, 1, L};
    }
  }
  for (int k = THR_COUNT - 1; k >= 0; k--) {
    double L = t->level[k];
    if (L > 0 && t->above[k] && force < L - hyst(L)) {
      t->above[k] = 0;
      ev[n++] = (thr_event_t){(thr_id_t)k, 0, L};
    }
  }
  for (int k = 0; k < THR_COUNT; k++)
    if (t->above[k]) t->time_above[k] += dt;
  if (in_contact) {
    t->contact_time += dt;
    t->contact_force_integral += force * dt;
  }
  if (pos) {
    if (t->have_pos) {
      double dx = pos[0] - t->last_pos[0], dy = pos[1] - t->last_pos[1], dz = pos[2] - t->last_pos[2];
      double d = sqrt(dx * dx + dy * dy + dz * dz);
      if (isfinite(d)) t->path_length += d;
    }
    memcpy(t->last_pos, pos, sizeof t->last_pos);
    t->have_pos = 1;
  } else {
    t->have_pos = 0;
  }
  return n;
}

double thr_mean_contact_force(const thr_tracker_t *t) {
  return t->contact_time > 0 ? t->contact_force_integral / t->contact_time : 0.0;
}
