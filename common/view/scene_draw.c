/* SPDX-License-Identifier: Apache-2.0 */
#include "view/scene_draw.h"

#include <math.h>

/* Proxy marker size relative to the tool tip: wide enough to show around the
 * shaft that passes through it, small enough not to hide the tip. */
#define PROXY_SCALE 0.8f

static double force_magnitude(const sv_tool_t *t) {
  if (!t->have_contact) return 0;
  return sqrt((double)t->force[0] * t->force[0] + (double)t->force[1] * t->force[1] +
              (double)t->force[2] * t->force[2]);
}

const uint8_t *scene_draw(render_t *r, const camera_t *cam, const scene_view_t *sv, int tools, verr_t *err) {
  render_begin(r, cam);
  for (int i = 0; i < SCENE_VIEW_MAX_ORGANS; i++) {
    const sv_organ_t *o = &sv->organs[i];
    if (!o->mesh.have_key) continue;
    if (render_mesh(r, o->mesh.cur, o->mesh.nverts, o->mesh.tris, o->mesh.ntris, o->rgb, err)) return NULL;
  }
  for (int i = 0; i < SCENE_VIEW_MAX_OBJECTS; i++) {
    const sv_object_t *o = &sv->objects[i];
    if (o->have) render_object(r, o->pos, o->radius, o->rgb);
  }
  if (tools) {
    for (int i = 0; i < SCENE_VIEW_MAX_TOOLS; i++) {
      const sv_tool_t *t = &sv->tools[i];
      if (t->have_pose) render_tool(r, t->tip, t->radius, t->length, t->have_contact && t->in_contact);
      if (t->have_contact && t->in_contact) render_proxy(r, t->proxy, PROXY_SCALE * t->radius);
    }
    int p = scene_view_primary_tool(sv);
    if (p >= 0) {
      const sv_tool_t *t = &sv->tools[p];
      render_force_bar_levels(r, force_magnitude(t), t->max_force, t->st, t->mpf, t->sft);
    }
  }
  return render_end(r);
}

void scene_draw_readouts(const camera_t *cam, const scene_view_t *sv, frame_row_t *row) {
  uint64_t t = scene_view_sim_time_ns(sv);
  row->sim_time_s = scene_view_any_keyframe(sv) ? (double)t * 1e-9 : -1;
  row->frame_seq = scene_view_frame_seq(sv);
  row->in_contact = 0;
  row->force_n = 0;
  row->tool_known = row->proxy_known = 0;
  int p = scene_view_primary_tool(sv);
  if (p < 0) return;
  const sv_tool_t *tool = &sv->tools[p];
  row->in_contact = tool->have_contact && tool->in_contact;
  row->force_n = force_magnitude(tool);
  if (tool->have_pose) {
    double tip[3] = {tool->tip[0], tool->tip[1], tool->tip[2]};
    row->tool_known = camera_project(cam, tip, &row->tool_px, &row->tool_py);
  }
  if (row->in_contact) {
    double q[3] = {tool->proxy[0], tool->proxy[1], tool->proxy[2]};
    row->proxy_known = camera_project(cam, q, &row->proxy_px, &row->proxy_py);
  }
}
