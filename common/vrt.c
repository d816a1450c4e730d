#define _GNU_SOURCE
#include "vrt.h"

#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

int vrt_parse_priority(const char *s) {
  char *end = NULL;
  errno = 0;
  long v = strtol(s, &end, 10);
  if (errno || end == s || *end || v < 1 || v > 99) return -1;
  return (int)v;
}

int vrt_make_realtime(int priority, const char *who, int quiet) {
  struct sched_param sp = {.sched_priority = priority};
  int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
  if (rc != 0) {
    fprintf(stderr, "%s: warning: SCHED_FIFO %d refused (%s); running at normal priority\n", who, priority,
            strerror(rc));
    return -1;
  }
  /* The sanitizers' shadow memory is terabytes of reserved address space:
   * locking it fails, which is worth a warning, not giving up the priority. */
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0)
    fprintf(stderr, "%s: warning: SCHED_FIFO %d but mlockall failed (%s); memory not locked\n", who, priority,
            strerror(errno));
  else if (!quiet)
    fprintf(stderr, "%s: loop at SCHED_FIFO priority %d, memory locked\n", who, priority);
  return 0;
}
