/* SPDX-License-Identifier: Apache-2.0 */
#include "vsignal.h"

#include <signal.h>
#include <string.h>

void vsignal_on(int sig, void (*handler)(int), int flags) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = handler;
  sa.sa_flags = flags;
  sigemptyset(&sa.sa_mask);
  sigaction(sig, &sa, NULL);
}

void vsignal_on_stop(void (*handler)(int), int flags) {
  vsignal_on(SIGINT, handler, flags);
  vsignal_on(SIGTERM, handler, flags);
}
