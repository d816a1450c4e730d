/* SPDX-License-Identifier: Apache-2.0 */
/* vstats: order statistics over a sample buffer, for benchmark tables and
 * the rate/latency summaries clients print on exit. */
#ifndef VISCERA_VSTATS_H
#define VISCERA_VSTATS_H

#include <stddef.h>

typedef struct vstats_summary {
  size_t n;
  double min, max, mean, median, p95, p99;
} vstats_summary_t;

/* Sorts `v` in place and summarises it. n == 0 gives all zeros. */
vstats_summary_t vstats_summarise(double *v, size_t n);

#endif
