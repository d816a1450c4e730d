/* SPDX-License-Identifier: Apache-2.0 */
#include "cpu_wake.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define CPU_WAKE_DEVICE "/dev/cpu_dma_latency"

int cpu_wake_parse(const char *s, int *us) {
  if (!s || !isdigit((unsigned char)s[0])) return -1; /* no sign, no blanks */
  char *end = NULL;
  errno = 0;
  long v = strtol(s, &end, 10);
  if (errno || *end || v < 0 || v > CPU_WAKE_MAX_US) return -1;
  *us = (int)v;
  return 0;
}

int cpu_wake_option(const char *prog, const char *arg, int *us) {
  if (!cpu_wake_parse(arg, us)) return 0;
  fprintf(stderr, "%s: --cpu-wake-latency '%s' is not a number of microseconds 0..%d\n", prog, arg ? arg : "",
          CPU_WAKE_MAX_US);
  return 2;
}

int cpu_wake_hold(cpu_wake_t *w, int max_us) {
  memset(w, 0, sizeof *w);
  w->fd = -1;
  w->max_us = max_us;
  int fd = open(CPU_WAKE_DEVICE, O_WRONLY | O_CLOEXEC);
  if (fd < 0) {
    int e = errno;
    snprintf(w->why, sizeof w->why, "%s: %s%s", CPU_WAKE_DEVICE, strerror(e),
             e == EACCES || e == EPERM ? " (needs root, or write access granted by a udev rule)" : "");
    return 0;
  }
  /* The kernel takes the bound as a binary 32-bit value; the request holds
   * while fd stays open (Documentation/power/pm_qos_interface.rst). */
  int32_t v = max_us;
  if (write(fd, &v, sizeof v) != (ssize_t)sizeof v) {
    int e = errno;
    snprintf(w->why, sizeof w->why, "%s: write: %s", CPU_WAKE_DEVICE, strerror(e));
    close(fd);
    return 0;
  }
  w->fd = fd;
  w->granted = 1;
  return 1;
}

void cpu_wake_release(cpu_wake_t *w) {
  if (w->fd >= 0) close(w->fd);
  w->fd = -1;
  w->granted = 0;
}

void cpu_wake_report(const cpu_wake_t *w, const char *who, FILE *log) {
  if (w->granted) {
    fprintf(log, "%s: CPU wake-up latency held at <= %d us while running (PM QoS; idle CPUs %s)\n", who, w->max_us,
            w->max_us == 0 ? "poll instead of sleeping" : "stay out of deeper idle states");
    return;
  }
  fprintf(log,
          "%s: warning: --cpu-wake-latency %d refused: %s; idle CPUs may sleep deeply and the step after each "
          "wake-up costs more\n",
          who, w->max_us, w->why);
}
