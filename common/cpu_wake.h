/* SPDX-License-Identifier: Apache-2.0 */
/* cpu_wake: keep the machine's idle CPUs able to wake within a bound, for
 * as long as a 1 kHz loop runs (Linux PM QoS: /dev/cpu_dma_latency).
 *
 * Why: a loop that sleeps between its 1 ms ticks lets its core go idle; a
 * deep idle state (on a virtual machine: the halt that hands the core back
 * to the host) costs the step after each wake-up its caches and time to
 * wake. On this project's 2-core KVM machine a busy gallbladder seat's
 * tissue step took 59-61 us after each sleep and 32 us with a bound of 0 us,
 * where idle CPUs poll instead of halting (docs/numerics.md §11.5). The
 * price: idle CPUs keep running (power, and a host sees the guest busy).
 * The poll runs in the kernel's idle task, so it takes no CPU time from any
 * process.
 *
 * Contract:
 * - The request is machine-wide and lasts while the descriptor stays open;
 *   cpu_wake_release (or the process's exit, a crash included) ends it.
 * - A refusal (no write access to /dev/cpu_dma_latency: root or a udev rule
 *   granting it; a kernel without PM QoS) is not an error: the loop runs as
 *   it would without the request, and the status names the reason.
 * - Not thread-safe: one owner (main) holds and releases it. */
#ifndef VISCERA_CPU_WAKE_H
#define VISCERA_CPU_WAKE_H

#include <stdio.h>

#define CPU_WAKE_MAX_US 10000 /* a bound beyond 10 ms would not help a 1 ms loop */

typedef struct cpu_wake {
  int fd;        /* open while the request is held; -1 otherwise */
  int max_us;    /* the bound asked for */
  int granted;   /* the kernel holds the request */
  char why[200]; /* refused: the reason */
} cpu_wake_t;

/* Parses a --cpu-wake-latency argument: a whole number of microseconds
 * 0..CPU_WAKE_MAX_US. Returns 0 and sets *us, or -1 (us untouched). */
int cpu_wake_parse(const char *s, int *us);

/* cpu_wake_parse for a program's option parser: on a bad argument prints
 * "PROG: --cpu-wake-latency 'ARG' is not a number of microseconds 0..MAX"
 * to stderr and returns 2 (the usage-error exit status); else 0. */
int cpu_wake_option(const char *prog, const char *arg, int *us);

/* Asks that no CPU take longer than max_us to wake. Fills *w; returns 1
 * when the request is held, 0 when refused (w->why says why). */
int cpu_wake_hold(cpu_wake_t *w, int max_us);

/* Ends a held request (no-op otherwise). */
void cpu_wake_release(cpu_wake_t *w);

/* Prints the outcome to `log`, prefixed "WHO: ": one line when held, a
 * warning when refused. Printed even by a --quiet program: the request is
 * a machine-wide setting, and whoever reads the log should know it held. */
void cpu_wake_report(const cpu_wake_t *w, const char *who, FILE *log);

#endif
