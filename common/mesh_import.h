/* SPDX-License-Identifier: Apache-2.0 */
/* mesh_import: any file assimp reads (OBJ, STL, PLY, glTF, ...) to one welded mesh_t.
 * All meshes of the file are merged with their node transforms applied; points and
 * lines are ignored; vertices with bit-identical positions are welded (files repeat a
 * position per normal/UV) and unreferenced vertices dropped, so the result is a
 * connected indexed surface. Vertices come in order of first use by the triangles,
 * so import(write_obj(import(f))) has the same vertex order and triangles as
 * import(f); positions agree to float precision (assimp parses text into floats,
 * not always to the nearest one). Units are the file's own.
 * On failure returns -1, leaves *out empty and names the file in err. Not thread-safe:
 * assimp's C API keeps its last error message in a global. */
#ifndef VISCERA_MESH_IMPORT_H
#define VISCERA_MESH_IMPORT_H

#include <stddef.h>

#include "mesh.h"
#include "verr.h"

typedef struct mesh_import_opts {
  size_t max_file_bytes; /* refuse larger files before parsing them */
  size_t max_triangles;  /* refuse scenes with more triangles (sum over meshes) */
} mesh_import_opts_t;

/* 1 GiB and 16 Mi triangles: far above any organ, low enough to fail cleanly. */
#define MESH_IMPORT_DEFAULT_MAX_FILE_BYTES ((size_t)1 << 30)
#define MESH_IMPORT_DEFAULT_MAX_TRIANGLES ((size_t)1 << 24)

mesh_import_opts_t mesh_import_default_opts(void);

int mesh_import(const char *path, mesh_t *out, verr_t *err);
/* opts == NULL means the defaults. */
int mesh_import_ex(const char *path, const mesh_import_opts_t *opts, mesh_t *out, verr_t *err);

#endif
