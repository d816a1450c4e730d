/* SPDX-License-Identifier: Apache-2.0 */
#include "replay_pause.h"

void rpause_set(rpause_t *p, bool paused, int64_t now) {
  if (paused == p->paused) return;
  if (paused) {
    p->since = now;
  } else if (now > p->since) {
    p->shift += now - p->since;
  }
  p->paused = paused;
}

int64_t rpause_due(const rpause_t *p, int64_t base_due) {
  if (p->paused) return INT64_MAX;
  /* saturate: a pathological shift must not wrap into the past */
  if (base_due > INT64_MAX - p->shift) return INT64_MAX;
  return base_due + p->shift;
}

void rpause_new_pass(rpause_t *p, int64_t now) {
  p->shift = 0;
  if (p->paused) p->since = now;
}
