/* SPDX-License-Identifier: Apache-2.0 */
/* topology_follow: what the runtime rebuilds when an organ's model changes
 * its surface topology (model.h: topology_version moved during a step, e.g.
 * adaptive refinement or simplification, or a cut).
 *
 * Everything that holds indices into the old surface is renewed: the
 * organ's AABB tree is rebuilt (its capacity follows the new triangle
 * count), the proxy_surface_t view takes the model's (possibly moved)
 * pointers and counts, and every proxy in contact with the organ is
 * re-attached to the same place on the new surface, so a tool pressing in
 * keeps its contact and its force does not jump:
 *   - models that refine in place (model.h surface_anchor/surface_locate:
 *     adaptive_mass_spring): the contact triangle's anchor (its coarse
 *     face) is captured before the step (topo_capture) and the proxy
 *     re-located inside it (surface_locate). Refinement puts new vertices at midpoints of the
 *     current positions, so the proxy point lies exactly on the refined
 *     surface and does not move at all; simplification moves it by the
 *     distance between the refined and coarse surface there.
 *   - any other model (cutting), or no triangle found there: the nearest point of the new surface whose
 *     rest normal faces the same way as the old contact normal (the same
 *     0.2 cosine the proxy uses to stay on its side of thin tissue).
 * The caller rebuilds the contact patches afterwards (scene_runtime.c).
 *
 * No allocation unless the topology changed: topo_capture only reads. The
 * rebuild allocates (a new tree); if it fails the organ's tree is dropped
 * and the proxy scans every triangle instead (same results, slower), and
 * the error is returned. Single-threaded, like the runtime. */
#ifndef VISCERA_TOPOLOGY_FOLLOW_H
#define VISCERA_TOPOLOGY_FOLLOW_H

#include <stddef.h>
#include <stdint.h>

#include "runtime/scene_runtime.h"
#include "verr.h"

/* Per tool, where its contact was before the organ's step. */
typedef struct topo_anchor {
  int in_contact;   /* the tool's proxy was on this organ */
  uint32_t face;    /* model.h surface_anchor of the contact triangle; else UINT32_MAX */
  double normal[3]; /* contact normal before the step */
} topo_anchor_t;

/* Before stepping organ `organ`: records each tool's anchor on it. */
void topo_capture(const runtime_t *rt, size_t organ, topo_anchor_t anchors[SCENE_MAX_TOOLS]);

/* After a step in which organ->model->topology_version moved: rebuilds the
 * tree, refreshes rt->surfaces[organ], re-attaches the proxies captured in
 * `anchors`, and sets organ->topology_version to the model's (also when it
 * fails). Returns 0, or -1 with err (tree rebuild failed: scan fallback). */
int topo_follow(runtime_t *rt, size_t organ, const topo_anchor_t anchors[SCENE_MAX_TOOLS], verr_t *err);

/* 3 x the longest rest edge of the model's surface: the proxy's cull bound
 * (edges may stretch while deformed; see runtime_init). */
double topo_max_edge_bound(const model_t *m);

#endif
