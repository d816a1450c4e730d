/* SPDX-License-Identifier: Apache-2.0 */
/* cpu_pin: keep a loop thread on chosen CPUs (a CPU list as taskset -c
 * writes it: "1", "0-3,6").
 *
 * Why: a 1 kHz physics loop shares its core with whatever else the machine
 * runs; on one machine that holds a lab's clients too, their threads run on
 * the loop's core between and within its steps (docs/numerics.md §11.5).
 * Pinning the loop to CPUs the rest is kept off (the rest started with
 * taskset, or a cpuset) gives it a core of its own, as isolcpus setups do.
 *
 * Contract:
 * - Only the CALLING thread is pinned (Linux applies affinity per thread);
 *   threads it creates afterwards inherit it, threads created before keep
 *   theirs.
 * - A refusal (a CPU outside the process's cpuset) is not an error for the
 *   caller's loop: it runs where it ran, and `why` says why.
 * - The list is untrusted input: only digits, ',' and '-', ascending
 *   ranges, CPUs that exist on this machine. */
#ifndef VISCERA_CPU_PIN_H
#define VISCERA_CPU_PIN_H

#include <stddef.h>
#include <stdint.h>

#define CPU_PIN_MAX 256 /* CPUs a list may name: 0..CPU_PIN_MAX-1 */

typedef struct cpu_pin {
  uint64_t mask[CPU_PIN_MAX / 64];
  int count;     /* CPUs in the set (> 0 once parsed) */
  char text[64]; /* the list as given, for messages */
} cpu_pin_t;

/* Parses `s`; 0 with *p filled, or -1 with what is wrong in why. */
int cpu_pin_parse(const char *s, cpu_pin_t *p, char *why, size_t whylen);

/* Pins the calling thread to p's CPUs; 0, or -1 with why. */
int cpu_pin_self(const cpu_pin_t *p, char *why, size_t whylen);

#endif
