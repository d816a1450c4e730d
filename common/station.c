/* SPDX-License-Identifier: Apache-2.0 */
#include "station.h"

#include <stddef.h>

int station_name_valid(const char *name) {
  if (!name) return 0;
  size_t n = 0;
  for (; name[n]; n++) {
    char c = name[n];
    int ok =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '.' || c == '-';
    if (!ok || n + 1 >= STATION_NAME_MAX) return 0;
  }
  return n > 0;
}
