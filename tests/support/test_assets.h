/* SPDX-License-Identifier: Apache-2.0 */
/* test_assets: the repository's assets in tests, stability cases and
 * benchmarks. The source tree is $VISCERA_SOURCE_DIR when set (ctest sets
 * it), else the tree this library was built from, so a test run by hand
 * from any build folder finds its meshes and scenes. A mesh that cannot be
 * loaded is reported on stdout by name (the caller decides whether that
 * fails or skips). Implemented in test_assets.c (viscera_test_support). */
#ifndef VISCERA_TEST_ASSETS_H
#define VISCERA_TEST_ASSETS_H

#include "mesh.h"
#include "mesh_import.h"

/* $VISCERA_SOURCE_DIR, or the source tree of the build. Never NULL. */
const char *test_source_dir(void);

/* Makes test_asset (and everything built on it: mesh loading, the
 * test_runtime scenes) read from the assets folder `dir` instead of
 * "<source>/assets" (a benchmark's ASSETS_DIR argument); NULL restores the
 * default. The string is copied. */
void test_assets_dir_set(const char *dir);

/* "<source>/assets/<sub>", or "<dir>/<sub>" after test_assets_dir_set (e.g. "meshes/kidney.obj", "scenes"); the result
 * is valid until the eighth call after this one. */
const char *test_asset(const char *sub);

/* Loads assets/meshes/<name> into *m: 0, or -1 after printing why. */
int test_mesh_load(const char *name, mesh_t *m);

/* The same for an organ by name: assets/meshes/<organ>.obj. */
int test_organ_load(const char *organ, mesh_t *m);

#endif
