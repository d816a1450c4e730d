/* test_tmpfile: writing a small input file (trajectory, input script...)
 * for a parser under test. The path is /tmp/viscera_test_<pid>_<name>, so
 * parallel test runs do not collide; the caller unlinks it. A file that
 * cannot be written ends the test (exit 1) naming the path: the checks
 * after it would be meaningless. Header-only. */
#ifndef VISCERA_TEST_TMPFILE_H
#define VISCERA_TEST_TMPFILE_H

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

/* Writes `text` to the temporary file `name`; returns its path, valid
 * until the next call. */
static inline const char *test_write_tmp(const char *name, const char *text) {
  static char path[256];
  snprintf(path, sizeof path, "/tmp/viscera_test_%d_%s", (int)getpid(), name);
  FILE *f = fopen(path, "w");
  if (!f || fputs(text, f) < 0 || fclose(f) != 0) {
    perror(path);
    exit(1);
  }
  return path;
}

#endif
