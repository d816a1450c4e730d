/* SPDX-License-Identifier: Apache-2.0 */
#include "measure_table.h"

#include <math.h>

static const rep_measure_def_t DEFS[REP_NMEASURES] = {
    {"peak_force_N", "peak force", "N", "%.2f"},
    {"mean_contact_force_N", "mean palpation force (in contact)", "N", "%.2f"},
    {"contact_time_s", "exploration (contact) time", "s", "%.2f"},
    {"time_to_first_contact_s", "time to first contact", "s", "%.2f"},
    {"operation_time_s", "operation time", "s", "%.2f"},
    {"time_above_ST_s", "time above ST", "s", "%.2f"},
    {"time_above_MPF_s", "time above MPF", "s", "%.2f"},
    {"time_above_SFT_s", "time above SFT", "s", "%.2f"},
    {"crossings_ST", "ST crossings", "", "%.0f"},
    {"crossings_MPF", "MPF crossings", "", "%.0f"},
    {"crossings_SFT", "SFT crossings", "", "%.0f"},
    {"path_length_cm", "tool path length", "cm", "%.1f"},
};

const rep_measure_def_t *rep_measure(int i) { return i >= 0 && i < REP_NMEASURES ? &DEFS[i] : NULL; }

double rep_measure_value(const rep_recording_t *r, int i) {
  const rep_summary_t *s = &r->sum;
  switch (i) {
  case 0:
    return s->peak_force;
  case 1:
    return s->contact_time > 0 ? s->mean_contact_force : NAN;
  case 2:
    return s->contact_time;
  case 3:
    return s->time_to_first_contact;
  case 4:
    return s->operation_time;
  case 5:
  case 6:
  case 7:
    /* an unset threshold has no time above it, not zero */
    return s->levels[i - 5] > 0 ? s->time_above[i - 5] : NAN;
  case 8:
  case 9:
  case 10:
    return s->levels[i - 8] > 0 ? s->crossings[i - 8] : NAN;
  case 11:
    return s->path_length * 100.0;
  }
  return NAN;
}
