/* SPDX-License-Identifier: Apache-2.0 */
/* The asset tool's usage errors, shared by its commands (asset_usage.h). */
#include "asset_usage.h"

#include <stdarg.h>
#include <stdio.h>

int bad_usage(const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  fprintf(stderr, "viscera-asset: ");
  vfprintf(stderr, fmt, ap);
  fprintf(stderr, "\n(run viscera-asset --help for usage)\n");
  va_end(ap);
  return EXIT_USAGE;
}
