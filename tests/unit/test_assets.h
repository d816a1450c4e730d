/* test_assets: loading the repository's asset meshes in tests and
 * benchmarks. The source tree is $VISCERA_SOURCE_DIR when set, else
 * "../.." (a test run from its build directory two levels down). A mesh
 * that cannot be loaded is reported on stdout by name (the caller decides
 * whether that fails or skips). Header-only. */
#ifndef VISCERA_TEST_ASSETS_H
#define VISCERA_TEST_ASSETS_H

#include <stdio.h>
#include <stdlib.h>

#include "mesh.h"
#include "mesh_import.h"

/* Loads assets/meshes/<name> into *m: 0, or -1 after printing why. */
static inline int test_mesh_load(const char *name, mesh_t *m) {
  const char *src = getenv("VISCERA_SOURCE_DIR");
  char path[4096];
  snprintf(path, sizeof path, "%s/assets/meshes/%s", src ? src : "../..", name);
  verr_t err;
  if (mesh_import(path, m, &err)) {
    printf("cannot load %s: %s\n", name, err.msg);
    return -1;
  }
  return 0;
}

#endif
