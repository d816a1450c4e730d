/* SPDX-License-Identifier: Apache-2.0 */
/* data_path: where a viscera binary finds its data files (scenes, meshes,
 * trajectories, Cyclone DDS configurations) from any working directory.
 *
 * Every root below has the source tree's layout (assets/scenes/...,
 * assets/trajectories/..., deploy/cyclonedds-loopback.xml); they are
 * searched in this order:
 *   0. $VISCERA_DATA_DIR (when set and non-empty),
 *   1. ../share/viscera next to the running binary's directory (an
 *      installed binary, wherever the tree was put: /usr from the .deb,
 *      /usr/local from cmake --install, a scratch root from dpkg -x),
 *   2. <CMAKE_INSTALL_PREFIX>/share/viscera as configured at build time,
 *   3. the source tree the binary was built from.
 * Pure lookups (stat, readlink), no state; thread-safe. */
#ifndef VISCERA_DATA_PATH_H
#define VISCERA_DATA_PATH_H

#include <stddef.h>

#define DATA_PATH_ROOTS 4
#define DATA_PATH_MAX 4096

/* The k-th root (k = 0..3 as above) into buf[cap]; NULL when that root is
 * not set (or does not fit). */
const char *data_path_root(int k, char *buf, size_t cap);

/* Finds `rel` (e.g. "deploy/cyclonedds-loopback.xml") under the first root
 * that has it; writes the full path into out[cap]. Returns 0, or -1 when no
 * root has it (out = ""). */
int data_path_find(const char *rel, char *out, size_t cap);

/* A file a user named (--scene, --trajectory): `path` itself when it exists
 * (relative to the working directory); otherwise, for a relative path, the
 * first of ROOT/subdir/path and ROOT/subdir/basename(path) that exists
 * (subdir e.g. "assets/scenes"). Returns 0 with out set, or -1 with out =
 * path (so the caller's error names what the user typed). */
int data_path_resolve(const char *path, const char *subdir, char *out, size_t cap);

#endif
