/* SPDX-License-Identifier: Apache-2.0 */
/* cpu_set_t and pthread_setaffinity_np are GNU extensions. */
#define _GNU_SOURCE
#include "cpu_pin.h"

#include <ctype.h>
#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Reads a CPU number at *s (digits only); -1 when there is none or it is
 * too large. */
static long cpu_number(const char **s) {
  if (!isdigit((unsigned char)**s)) return -1;
  long v = 0;
  while (isdigit((unsigned char)**s)) {
    v = v * 10 + (**s - '0');
    if (v >= CPU_PIN_MAX) return -1;
    (*s)++;
  }
  return v;
}

int cpu_pin_parse(const char *s, cpu_pin_t *p, char *why, size_t whylen) {
  memset(p, 0, sizeof *p);
  if (!s || !*s || strlen(s) >= sizeof p->text) {
    snprintf(why, whylen, "expected a CPU list such as 1 or 0-3,6");
    return -1;
  }
  snprintf(p->text, sizeof p->text, "%s", s);
  long ncpu = sysconf(_SC_NPROCESSORS_CONF);
  const char *c = s;
  for (;;) {
    long a = cpu_number(&c), b = a;
    if (a >= 0 && *c == '-') {
      c++;
      b = cpu_number(&c);
    }
    if (a < 0 || b < a || (*c && *c != ',')) {
      snprintf(why, whylen, "'%s' is not a CPU list such as 1 or 0-3,6 (CPUs 0..%d)", s, CPU_PIN_MAX - 1);
      return -1;
    }
    if (ncpu > 0 && b >= ncpu) {
      snprintf(why, whylen, "CPU %ld of '%s' is not on this machine (CPUs 0..%ld)", b, s, ncpu - 1);
      return -1;
    }
    for (long k = a; k <= b; k++) {
      uint64_t bit = 1ull << (k % 64);
      if (!(p->mask[k / 64] & bit)) p->count++;
      p->mask[k / 64] |= bit;
    }
    if (!*c) return 0;
    c++; /* ',' */
  }
}

int cpu_pin_self(const cpu_pin_t *p, char *why, size_t whylen) {
  cpu_set_t set;
  CPU_ZERO(&set);
  for (int k = 0; k < CPU_PIN_MAX && k < CPU_SETSIZE; k++)
    if (p->mask[k / 64] & (1ull << (k % 64))) CPU_SET(k, &set);
  int e = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
  if (e) {
    snprintf(why, whylen, "CPUs %s: %s", p->text, strerror(e));
    return -1;
  }
  return 0;
}
