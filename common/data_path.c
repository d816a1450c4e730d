/* SPDX-License-Identifier: Apache-2.0 */
#include "data_path.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Set by common/CMakeLists.txt for this file only. */
#ifndef VISCERA_INSTALL_DATADIR
#define VISCERA_INSTALL_DATADIR ""
#endif
#ifndef VISCERA_SOURCE_ROOT
#define VISCERA_SOURCE_ROOT ""
#endif

/* <dir of /proc/self/exe>/../share/viscera into buf. */
static const char *exe_root(char *buf, size_t cap) {
  char exe[DATA_PATH_MAX];
  ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (n <= 0) return NULL;
  exe[n] = 0;
  char *slash = strrchr(exe, '/');
  if (!slash) return NULL;
  *slash = 0;
  int w = snprintf(buf, cap, "%s/../share/viscera", exe);
  return w > 0 && (size_t)w < cap ? buf : NULL;
}

const char *data_path_root(int k, char *buf, size_t cap) {
  const char *r = NULL;
  if (k == 0) r = getenv("VISCERA_DATA_DIR");
  if (k == 1) return exe_root(buf, cap);
  if (k == 2) r = VISCERA_INSTALL_DATADIR;
  if (k == 3) r = VISCERA_SOURCE_ROOT;
  if (!r || !*r || strlen(r) >= cap) return NULL;
  return strcpy(buf, r);
}

static int is_file(const char *p) {
  struct stat st;
  return stat(p, &st) == 0 && S_ISREG(st.st_mode);
}

/* root/a[/b] into out; 0 when it fits and names a regular file. */
static int try_join(char *out, size_t cap, const char *root, const char *a, const char *b) {
  int n = b ? snprintf(out, cap, "%s/%s/%s", root, a, b) : snprintf(out, cap, "%s/%s", root, a);
  return n > 0 && (size_t)n < cap && is_file(out) ? 0 : -1;
}

int data_path_find(const char *rel, char *out, size_t cap) {
  if (!cap) return -1;
  char rb[DATA_PATH_MAX];
  for (int k = 0; k < DATA_PATH_ROOTS; k++) {
    const char *root = data_path_root(k, rb, sizeof rb);
    if (root && try_join(out, cap, root, rel, NULL) == 0) return 0;
  }
  out[0] = 0;
  return -1;
}

int data_path_resolve(const char *path, const char *subdir, char *out, size_t cap) {
  if (!cap) return -1;
  if (is_file(path) || path[0] == '/' || !path[0]) {
    snprintf(out, cap, "%s", path);
    return is_file(path) ? 0 : -1;
  }
  const char *base = strrchr(path, '/');
  base = base ? base + 1 : path;
  char rb[DATA_PATH_MAX];
  for (int k = 0; k < DATA_PATH_ROOTS; k++) {
    const char *root = data_path_root(k, rb, sizeof rb);
    if (!root) continue;
    if (try_join(out, cap, root, subdir, path) == 0) return 0;
    if (base != path && try_join(out, cap, root, subdir, base) == 0) return 0;
  }
  snprintf(out, cap, "%s", path);
  return -1;
}
