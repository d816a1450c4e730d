/* SPDX-License-Identifier: Apache-2.0 */
#include "physics/model_volume.h"

#include <math.h>
#include <string.h>

#include "tet_embed.h"

static double largest_extent(const tet_mesh_t *t) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < t->nnodes; i++)
    for (int k = 0; k < 3; k++) lo[k] = fmin(lo[k], t->x[3 * i + k]), hi[k] = fmax(hi[k], t->x[3 * i + k]);
  return fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
}

int model_volume_obtain(const model_params_t *p, tet_mesh_t *tm, tet_embedding_t *emb, verr_t *err) {
  const mesh_t *surf = p->surface;
  memset(emb, 0, sizeof *emb);
  if (!p->volume) {
    tet_build_report_t rep;
    verr_t sub;
    if (tet_mesh_build(surf, p->cfg->solver.tet_size, tm, emb, &rep, &sub))
      return verr_set(err, "cannot build a tetrahedral mesh: %s", sub.msg);
    return 0;
  }
  if (tet_mesh_copy(tm, p->volume, err)) return -1;
  tet_embed_report_t rep;
  if (tet_embed_points(tm, surf->pos, surf->nverts, emb, &rep, err)) {
    tet_mesh_free(tm);
    return -1;
  }
  double ext = largest_extent(tm);
  if (rep.max_distance > MODEL_VOLUME_MAX_OUTSIDE * ext) {
    verr_set(err,
             "the surface mesh lies outside its tetrahedral mesh: %zu of %zu vertices, up to %.3g m away (the "
             "volume spans %.3g m; at most %g of that is taken): do the two files have the same units and placement?",
             rep.outside, surf->nverts, rep.max_distance, ext, MODEL_VOLUME_MAX_OUTSIDE);
    tet_mesh_free(tm);
    tet_embedding_free(emb);
    return -1;
  }
  return 0;
}
