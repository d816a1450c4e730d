/* SPDX-License-Identifier: Apache-2.0 */
#include "mesh_dump.h"

#include <stdio.h>

#include "mesh.h"

static int dump_one(const organ_state_t *o, int id, const char *path, verr_t *err) {
  mesh_t m;
  if (mesh_alloc(&m, o->nverts, o->ntris, err)) return -1;
  for (size_t i = 0; i < 3 * o->nverts; i++) m.pos[i] = o->cur[i];
  for (size_t i = 0; i < 3 * o->ntris; i++) m.tris[i] = o->tris[i];
  char comment[128];
  snprintf(comment, sizeof comment, "organ %d topology %u keyframe %u frame %lld", id, o->topology_version,
           o->keyframe_seq, organ_state_frame_seq(o));
  int rc = mesh_write_obj(&m, path, comment, err);
  mesh_free(&m);
  return rc;
}

int mesh_dump_obj(const scene_view_t *sv, const char *path, verr_t *err) {
  int n = 0;
  for (int i = 0; i < SCENE_VIEW_MAX_ORGANS; i++) n += sv->organs[i].mesh.have_key;
  int written = 0;
  for (int i = 0; i < SCENE_VIEW_MAX_ORGANS; i++) {
    const organ_state_t *o = &sv->organs[i].mesh;
    if (!o->have_key) continue;
    char p[4096];
    int len = n > 1 ? snprintf(p, sizeof p, "%s.%d", path, i) : snprintf(p, sizeof p, "%s", path);
    if (len >= (int)sizeof p) return verr_set(err, "%s: path too long", path);
    if (dump_one(o, i, p, err)) return -1;
    written++;
  }
  return written;
}
