/* SPDX-License-Identifier: Apache-2.0 */
/* vtime: monotonic time in nanoseconds and absolute sleeps for fixed-rate loops. */
#ifndef VISCERA_VTIME_H
#define VISCERA_VTIME_H

#include <stdint.h>

/* CLOCK_MONOTONIC in ns. Thread-safe. */
uint64_t vtime_mono_ns(void);
/* CLOCK_REALTIME in ns (for DDS source timestamps and recordings). */
int64_t vtime_wall_ns(void);
/* CPU time this thread has used, in ns (CLOCK_THREAD_CPUTIME_ID): the work a
 * loop did, without the time the scheduler gave to other processes. */
uint64_t vtime_thread_cpu_ns(void);
/* Sleep until the absolute CLOCK_MONOTONIC time t_ns; returns at once if past. */
void vtime_sleep_until(uint64_t t_ns);

#endif
