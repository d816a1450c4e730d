/* SPDX-License-Identifier: Apache-2.0 */
#include "verr.h"

#include <stdarg.h>
#include <stdio.h>

int verr_set(verr_t *err, const char *fmt, ...) {
  if (err) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->msg, sizeof err->msg, fmt, ap);
    va_end(ap);
  }
  return -1;
}
