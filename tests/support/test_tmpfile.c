/* SPDX-License-Identifier: Apache-2.0 */
/* test_tmpfile.c: temporary files of a test (test_tmpfile.h). */
#include "test_tmpfile.h"

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

const char *test_tmp_path(const char *name) {
  static char path[4][256];
  static unsigned next;
  char *p = path[next++ % 4];
  snprintf(p, sizeof path[0], "/tmp/viscera_test_%d_%s", (int)getpid(), name);
  return p;
}

const char *test_write_tmp(const char *name, const char *text) {
  const char *path = test_tmp_path(name);
  FILE *f = fopen(path, "w");
  if (!f || fputs(text, f) < 0 || fclose(f) != 0) {
    perror(path);
    exit(1);
  }
  return path;
}
