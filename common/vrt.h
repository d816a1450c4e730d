/* SPDX-License-Identifier: Apache-2.0 */
/* vrt: make one loop thread real-time (SCHED_FIFO, memory locked), shared by
 * the server's physics loop and the haptic client's 1 kHz loop.
 *
 * Contract:
 * - Only the CALLING thread changes policy (Linux applies the scheduler per
 *   thread); threads created before the call (Cyclone DDS's receive, event
 *   and lease threads, the checkpoint writer) keep SCHED_OTHER, and so does
 *   every thread the real-time thread creates later (SCHED_RESET_ON_FORK), so
 *   exactly one thread of the process runs FIFO.
 * - A refusal (no CAP_SYS_NICE, RLIMIT_RTPRIO too low, a cgroup without RT
 *   budget) is not an error: the thread stays as it was and the caller runs on
 *   at normal priority; the warning names the reason.
 * - Memory: locked (mlockall) only after the priority was granted, because a
 *   page fault in a FIFO loop costs what FIFO was meant to save. Current and
 *   future pages when the process may lock without limit (CAP_IPC_LOCK or an
 *   unlimited RLIMIT_MEMLOCK); otherwise current pages only, since MCL_FUTURE
 *   under a finite limit makes a later malloc fail once the limit is reached.
 *   An AddressSanitizer build does not lock (ASan reserves terabytes of
 *   shadow and intercepts mlockall as a no-op): a warning says so.
 * - The caller's loop must sleep every period: the kernel's RT throttling
 *   (sched_rt_runtime_us, by default 950000 of every 1000000 us) is only the
 *   safety net that keeps a runaway FIFO thread from freezing its core. A
 *   warning says when that net is off (sched_rt_runtime_us = -1). */
#ifndef VISCERA_VRT_H
#define VISCERA_VRT_H

#include <stdio.h>

#define VRT_PRIORITY_MIN 1
#define VRT_PRIORITY_MAX 99

/* Parses an --rt-priority argument: a whole number 1..99 (SCHED_FIFO's
 * range on Linux). Returns 0 and sets *prio, or -1 (prio untouched). */
int vrt_parse_priority(const char *s, int *prio);

typedef enum vrt_mem { VRT_MEM_NONE = 0, VRT_MEM_CURRENT, VRT_MEM_ALL } vrt_mem_t;

typedef struct vrt_status {
  int priority;            /* what was asked */
  int granted;             /* the calling thread now runs SCHED_FIFO at priority */
  vrt_mem_t mem;           /* what mlockall locked (VRT_MEM_NONE when not granted) */
  char why[200];           /* refused: the reason */
  char mem_note[240];      /* memory not (fully) locked: why; "" when all locked */
  char throttle_note[160]; /* RT throttling off: the warning text; "" otherwise */
} vrt_status_t;

/* Makes the calling thread SCHED_FIFO at `priority` (1..99) and locks memory
 * as the contract says. Fills *st; returns 1 when granted, 0 when refused. */
int vrt_enter(int priority, vrt_status_t *st);

/* Prints the outcome to `log`, each line prefixed "WHO: ": one line when
 * granted (unless quiet), and every warning (refusal, memory, throttling)
 * whatever quiet says. `what` names the thread ("loop", "physics loop"). */
void vrt_report(const vrt_status_t *st, const char *who, const char *what, int quiet, FILE *log);

/* vrt_enter + vrt_report; returns 1 when granted, 0 when refused. */
int vrt_make_realtime(int priority, const char *who, const char *what, int quiet, FILE *log);

#endif
