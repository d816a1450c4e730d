/* SPDX-License-Identifier: Apache-2.0 */
/* SCHED_RESET_ON_FORK is a GNU/Linux extension of <sched.h>. */
#define _GNU_SOURCE
#include "vrt.h"

#include <ctype.h>
#include <errno.h>
#include <sched.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>

#if defined(__SANITIZE_ADDRESS__)
#define VRT_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define VRT_ASAN 1
#endif
#endif

#define CAP_IPC_LOCK_BIT 14 /* linux/capability.h; not worth libcap for one bit */

int vrt_parse_priority(const char *s, int *prio) {
  if (!s || !isdigit((unsigned char)s[0])) return -1; /* no sign, no blanks */
  char *end = NULL;
  errno = 0;
  long v = strtol(s, &end, 10);
  if (errno || *end || v < VRT_PRIORITY_MIN || v > VRT_PRIORITY_MAX) return -1;
  *prio = (int)v;
  return 0;
}

#ifndef VRT_ASAN
/* Whether this thread holds CAP_IPC_LOCK (exempts it from RLIMIT_MEMLOCK). */
static int has_ipc_lock(void) {
  FILE *f = fopen("/proc/thread-self/status", "r");
  if (!f) return 0;
  char line[256];
  unsigned long long eff = 0;
  int found = 0;
  while (!found && fgets(line, sizeof line, f)) found = sscanf(line, "CapEff: %llx", &eff) == 1;
  fclose(f);
  return found && ((eff >> CAP_IPC_LOCK_BIT) & 1ull);
}
#endif

static void lock_memory(vrt_status_t *st) {
#ifdef VRT_ASAN
  st->mem = VRT_MEM_NONE;
  snprintf(st->mem_note, sizeof st->mem_note,
           "AddressSanitizer build: its terabytes of shadow cannot be locked and ASan turns mlockall into a no-op");
#else
  struct rlimit rl = {0, 0};
  int unlimited = getrlimit(RLIMIT_MEMLOCK, &rl) == 0 && rl.rlim_cur == RLIM_INFINITY;
  int all = unlimited || has_ipc_lock();
  if (mlockall(MCL_CURRENT | (all ? MCL_FUTURE : 0)) != 0) {
    int e = errno;
    st->mem = VRT_MEM_NONE;
    snprintf(st->mem_note, sizeof st->mem_note, "mlockall: %s (RLIMIT_MEMLOCK %llu KiB, no CAP_IPC_LOCK)", strerror(e),
             (unsigned long long)rl.rlim_cur / 1024);
    return;
  }
  st->mem = all ? VRT_MEM_ALL : VRT_MEM_CURRENT;
  if (!all)
    snprintf(st->mem_note, sizeof st->mem_note,
             "memory allocated from now on is not locked: RLIMIT_MEMLOCK is %llu KiB without CAP_IPC_LOCK, and "
             "locking future pages would make an allocation past it fail",
             (unsigned long long)rl.rlim_cur / 1024);
#endif
}

/* RT throttling off means a FIFO thread that stops sleeping owns its core. */
static void check_throttling(vrt_status_t *st) {
  FILE *f = fopen("/proc/sys/kernel/sched_rt_runtime_us", "r");
  if (!f) return;
  long runtime = 0;
  if (fscanf(f, "%ld", &runtime) == 1 && runtime < 0)
    snprintf(st->throttle_note, sizeof st->throttle_note,
             "RT throttling is off (sched_rt_runtime_us = -1): nothing stops a FIFO thread that cannot keep up "
             "from holding its core");
  fclose(f);
}

int vrt_enter(int priority, vrt_status_t *st) {
  memset(st, 0, sizeof *st);
  st->priority = priority;
  if (priority < VRT_PRIORITY_MIN || priority > VRT_PRIORITY_MAX) {
    snprintf(st->why, sizeof st->why, "priority %d is outside %d..%d", priority, VRT_PRIORITY_MIN, VRT_PRIORITY_MAX);
    return 0;
  }
  /* pid 0 = the calling thread (Linux schedules threads, not processes).
   * RESET_ON_FORK: threads this one creates later (Cyclone may start one)
   * begin as SCHED_OTHER instead of inheriting FIFO. */
  struct sched_param sp = {.sched_priority = priority};
  if (sched_setscheduler(0, SCHED_FIFO | SCHED_RESET_ON_FORK, &sp) != 0) {
    int e = errno;
    snprintf(st->why, sizeof st->why, "%s%s", strerror(e),
             e == EPERM ? ": needs root, CAP_SYS_NICE or an RLIMIT_RTPRIO (ulimit -r, LimitRTPRIO=) this high" : "");
    return 0;
  }
  st->granted = 1;
  lock_memory(st);
  check_throttling(st);
  return 1;
}

void vrt_report(const vrt_status_t *st, const char *who, const char *what, int quiet, FILE *log) {
  if (!st->granted) {
    fprintf(log, "%s: warning: SCHED_FIFO %d refused (%s); running at normal priority\n", who, st->priority, st->why);
    return;
  }
  if (st->mem_note[0]) fprintf(log, "%s: warning: memory not fully locked (%s)\n", who, st->mem_note);
  if (st->throttle_note[0]) fprintf(log, "%s: warning: %s\n", who, st->throttle_note);
  if (!quiet)
    fprintf(log, "%s: %s at SCHED_FIFO priority %d, %s\n", who, what, st->priority,
            st->mem == VRT_MEM_ALL       ? "memory locked"
            : st->mem == VRT_MEM_CURRENT ? "current memory locked"
                                         : "memory not locked");
}

int vrt_make_realtime(int priority, const char *who, const char *what, int quiet, FILE *log) {
  vrt_status_t st;
  int granted = vrt_enter(priority, &st);
  vrt_report(&st, who, what, quiet, log);
  return granted;
}
