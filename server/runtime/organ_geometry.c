/* SPDX-License-Identifier: Apache-2.0 */
#include "runtime/organ_geometry.h"

#include <string.h>

#include "mesh_import.h"
#include "tet_embed.h"
#include "volume_mesh.h"

static void place(double *x, size_t n, const scene_organ_t *cfg) {
  for (size_t i = 0; i < n; i++)
    for (int k = 0; k < 3; k++) x[3 * i + k] = x[3 * i + k] * cfg->scale + cfg->position[k];
}

int organ_geometry_load(const scene_organ_t *cfg, mesh_t *surface, tet_mesh_t *volume, verr_t *err) {
  memset(surface, 0, sizeof *surface);
  memset(volume, 0, sizeof *volume);
  if (cfg->volume[0]) {
    if (volume_import(cfg->volume, volume, NULL, err)) return -1;
    place(volume->x, volume->nnodes, cfg);
  }
  int rc;
  if (cfg->mesh[0]) {
    rc = mesh_import(cfg->mesh, surface, err);
    if (!rc) place(surface->pos, surface->nverts, cfg);
  } else {
    verr_t e;
    rc = tet_mesh_boundary(volume, surface, NULL, NULL, &e);
    if (rc) verr_set(err, "%s: its boundary: %s", cfg->volume, e.msg);
  }
  if (rc) tet_mesh_free(volume);
  return rc;
}
