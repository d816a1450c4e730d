/* SPDX-License-Identifier: Apache-2.0 */
/* test_rollback_report: rolled-back steps are reported at once the first
 * time, then at most once per `every` steps with the count held back, by
 * the step count alone (issue 15: one event and one log line per step). */
#include "check.h"
#include "runtime/rollback_report.h"

int main(void) {
  rollback_report_t r;
  uint64_t n = 0;
  rollback_report_init(&r, 1000);
  CHECK(rollback_report_note(&r, 5, 0, &n) == 0); /* nothing rolled: nothing said */
  CHECK(rollback_report_note(&r, 10, 1, &n) == 1 && n == 1);
  /* Every step rolled back for 10 s of 1 kHz steps: 10 reports, not 10,000. */
  uint64_t total = 1, reports = 1;
  for (uint64_t s = 11; s < 10011; s++) {
    if (rollback_report_note(&r, s, 2, &n)) {
      reports++;
      total += n;
    }
  }
  CHECK(reports == 11);
  CHECK(total + rollback_report_pending(&r) == 1 + 2 * 10000);
  CHECK(r.suppressed == 10000 - 10);
  /* After a quiet spell the next one reports at once. */
  n = 0;
  CHECK(rollback_report_note(&r, 50000, 1, &n) == 1 && n == 1 + rollback_report_pending(&r) + n - n);
  rollback_report_init(&r, 0); /* every 0 taken as 1: each step may report */
  CHECK(rollback_report_note(&r, 1, 1, &n) == 1 && rollback_report_note(&r, 2, 1, &n) == 1);
  return check_report("test_rollback_report");
}
