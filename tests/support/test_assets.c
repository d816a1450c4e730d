/* SPDX-License-Identifier: Apache-2.0 */
/* test_assets.c: asset paths and mesh loading for tests (test_assets.h). */
#include "test_assets.h"

#include <stdio.h>
#include <stdlib.h>

#ifndef VISCERA_TEST_SOURCE_DIR
#define VISCERA_TEST_SOURCE_DIR "."
#endif

const char *test_source_dir(void) {
  const char *src = getenv("VISCERA_SOURCE_DIR");
  return src && *src ? src : VISCERA_TEST_SOURCE_DIR;
}

static char assets_dir[2048]; /* "" = <source>/assets */

void test_assets_dir_set(const char *dir) { snprintf(assets_dir, sizeof assets_dir, "%s", dir ? dir : ""); }

const char *test_asset(const char *sub) {
  static char buf[8][4096];
  static unsigned next;
  char *p = buf[next++ % 8];
  if (assets_dir[0])
    snprintf(p, sizeof buf[0], "%s/%s", assets_dir, sub);
  else
    snprintf(p, sizeof buf[0], "%s/assets/%s", test_source_dir(), sub);
  return p;
}

int test_mesh_load(const char *name, mesh_t *m) {
  char sub[1024];
  snprintf(sub, sizeof sub, "meshes/%s", name);
  verr_t err;
  if (mesh_import(test_asset(sub), m, &err)) {
    printf("cannot load %s: %s\n", name, err.msg);
    return -1;
  }
  return 0;
}

int test_organ_load(const char *organ, mesh_t *m) {
  char name[256];
  snprintf(name, sizeof name, "%s.obj", organ);
  return test_mesh_load(name, m);
}
