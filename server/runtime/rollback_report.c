/* SPDX-License-Identifier: Apache-2.0 */
#include "runtime/rollback_report.h"

void rollback_report_init(rollback_report_t *r, uint64_t every) {
  *r = (rollback_report_t){.every = every ? every : 1};
}

int rollback_report_note(rollback_report_t *r, uint64_t step, int rolled, uint64_t *count) {
  if (rolled <= 0) return 0;
  r->pending += (uint64_t)rolled;
  if (r->reported && step - r->last_step < r->every) {
    r->suppressed++;
    return 0;
  }
  *count = r->pending;
  r->pending = 0;
  r->last_step = step;
  r->reported = 1;
  r->reports++;
  return 1;
}

uint64_t rollback_report_pending(const rollback_report_t *r) { return r->pending; }
