/* SPDX-License-Identifier: Apache-2.0 */
#include "runtime/scene_runtime.h"

#include "runtime/topology_follow.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "interaction/shaft.h"
#include "mesh_admit.h"
#include "runtime/organ_geometry.h"
#include "runtime/step_cut.h"
#include "runtime/step_tools.h"
#include "vmath.h"

static void apply_contacts(model_t *m, void *vctx);

/* A problem of the organ's mesh or volume file, at the line of the key that
 * names that file: `volume:` when the message is about it, else `mesh:`. */
static int file_error(verr_t *err, const scene_t *sc, const scene_organ_t *cfg, uint32_t id, const char *what) {
  bool volume = cfg->volume[0] && (!cfg->mesh[0] || strstr(what, cfg->volume));
  int line = volume ? cfg->volume_line : cfg->mesh_line;
  return verr_set(err, "%s:%d: field 'organs[%u].%s': organ '%s'%s%s%s: %s", sc->path, line ? line : cfg->line, id,
                  volume ? "volume" : "mesh", cfg->name, cfg->model[0] ? " (model " : "", cfg->model,
                  cfg->model[0] ? ")" : "", what);
}

static int organ_init(organ_rt_t *o, runtime_t *rt, const scene_organ_t *cfg, uint32_t id, double tool_k, verr_t *err) {
  const scene_t *sc = &rt->scene;
  memset(o, 0, sizeof *o);
  o->cfg = cfg;
  o->id = id;
  o->rt = rt;
  verr_t e;
  tet_mesh_t volume = {0};
  if (organ_geometry_load(cfg, &o->rest, &volume, &e)) return file_error(err, sc, cfg, id, e.msg);
  /* The defects no model can take are refused, the ones with one right
   * answer repaired (mesh_admit.h); the volume models need a closed
   * surface, the surface ones also take a sheet. */
  mesh_admit_opts_t ao = {.allow_open = strcmp(cfg->model, "mass_spring_tet") && strcmp(cfg->model, "pbd") &&
                                        strcmp(cfg->model, "xpbd"),
                          .min_size = MESH_ADMIT_MIN_SIZE,
                          .max_size = MESH_ADMIT_MAX_SIZE};
  if (mesh_admit(&o->rest, &ao, cfg->mesh[0] ? cfg->mesh : cfg->volume, o->mesh_note, sizeof o->mesh_note, &e)) {
    mesh_free(&o->rest);
    tet_mesh_free(&volume);
    return file_error(err, sc, cfg, id, e.msg);
  }
  /* The proxy spring acts on the contact vertices like an extra home
   * spring, so explicit schemes include the stiffest tool in their bound. */
  model_params_t mp = {
      .cfg = cfg, .surface = &o->rest, .dt = sc->dt, .tool_stiffness = tool_k, .volume = volume.ntets ? &volume : NULL};
  v3_copy(mp.gravity, sc->gravity);
  o->model = model_create(&mp, &e);
  tet_mesh_free(&volume);
  if (!o->model) {
    mesh_free(&o->rest);
    return verr_set(err, "%s:%d: %s", sc->path, cfg->line, e.msg);
  }
  o->model->hook = apply_contacts;
  o->model->hook_ctx = o;
  if (sc->sleep_speed > 0 && organ_sleep_init(&o->sleep, o->model->nsurf, &e)) {
    model_destroy(o->model);
    o->model = NULL;
    mesh_free(&o->rest);
    return verr_set(err, "%s:%d: organ '%s': %s", sc->path, cfg->line, cfg->name, e.msg);
  }
  return 0;
}

int runtime_init(runtime_t *rt, const scene_t *scene, verr_t *err) {
  memset(rt, 0, sizeof *rt);
  rt->scene = *scene;
  rt->cull.patch_scale = rt->cull.shaft_scale = 1;
  double tool_k = 0;
  for (size_t t = 0; t < scene->ntools; t++)
    if (scene->tools[t].stiffness > tool_k) tool_k = scene->tools[t].stiffness;
  double bmin[3] = {INFINITY, INFINITY, INFINITY}, bmax[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < scene->norgans; i++) {
    if (organ_init(&rt->organs[i], rt, &rt->scene.organs[i], (uint32_t)i, tool_k, err)) {
      runtime_destroy(rt);
      return -1;
    }
    rt->norgans++;
    organ_rt_t *o = &rt->organs[i];
    const model_t *m = o->model;
    /* Edges may stretch while deformed; 3x the longest rest edge is far
     * beyond what the home springs allow and keeps the proxy cull exact.
     * Each triangle edge counts once per triangle: a closed mesh counts
     * every edge twice, which leaves the mean as it is. */
    double max_edge = 0, mean_edge = 0, tool_r = 0;
    for (size_t t = 0; t < m->nsurf_tris; t++)
      for (int k = 0; k < 3; k++) {
        const uint32_t *tri = m->surf_tris + 3 * t;
        double len = v3_dist(m->surf_rest + 3 * tri[k], m->surf_rest + 3 * tri[(k + 1) % 3]);
        max_edge = fmax(max_edge, len);
        mean_edge += len;
      }
    if (m->nsurf_tris) mean_edge /= 3.0 * (double)m->nsurf_tris;
    for (size_t t = 0; t < scene->ntools; t++) tool_r = fmax(tool_r, scene->tools[t].radius);
    o->patch_radius = fmax(2 * tool_r, 1.5 * mean_edge);
    rt->surfaces[i] = (proxy_surface_t){
        .x = m->surf_x, .tris = m->surf_tris, .ntris = m->nsurf_tris, .max_edge = 3 * max_edge, .x_rest = m->surf_rest};
    verr_t te;
    if (aabb_tree_build(&o->tree, m->surf_x, m->nsurf, m->surf_tris, m->nsurf_tris, &te)) {
      verr_set(err, "%s:%d: organ '%s': %s", rt->scene.path, o->cfg->line, o->cfg->name, te.msg);
      runtime_destroy(rt);
      return -1;
    }
    rt->surfaces[i].tree = &o->tree;
    if (vertex_cull_setup(&o->cull, m->nsurf, m->surf_tris, m->nsurf_tris, &te)) {
      verr_set(err, "%s:%d: organ '%s': %s", rt->scene.path, o->cfg->line, o->cfg->name, te.msg);
      runtime_destroy(rt);
      return -1;
    }
    o->topology_version = m->topology_version;
    o->vn_rest = malloc(3 * m->nsurf * sizeof *o->vn_rest);
    if (!o->vn_rest) {
      verr_set(err, "%s:%d: organ '%s': out of memory", rt->scene.path, o->cfg->line, o->cfg->name);
      runtime_destroy(rt);
      return -1;
    }
    proxy_vertex_normals(m->nsurf, m->surf_rest, m->nsurf_tris, m->surf_tris, o->vn_rest);
    rt->surfaces[i].vn = o->vn_rest;
    rt->surfaces[i].nvn = m->nsurf;
    double lo[3], hi[3];
    mesh_bounds(&o->rest, lo, hi);
    for (int k = 0; k < 3; k++) {
      bmin[k] = fmin(bmin[k], lo[k]);
      bmax[k] = fmax(bmax[k], hi[k]);
    }
  }
  /* Tools may roam a generous box around the organs; beyond it a command is
   * a corrupt sample, not a hand movement. */
  double diag = v3_dist(bmin, bmax), margin = fmax(1.0, 2 * diag);
  for (int k = 0; k < 3; k++) {
    rt->workspace.min[k] = bmin[k] - margin;
    rt->workspace.max[k] = bmax[k] + margin;
  }
  rt->ntools = scene->ntools;
  for (size_t t = 0; t < scene->ntools; t++) {
    rt->tools[t].cfg = &rt->scene.tools[t];
    proxy_reset(&rt->tools[t].proxy);
  }
  if (interact_init(rt, err) || scalpel_init(rt, err)) {
    runtime_destroy(rt);
    return -1;
  }
  return 0;
}

void runtime_destroy(runtime_t *rt) {
  scalpel_destroy(rt); /* before the models it cuts */
  for (size_t i = 0; i < rt->norgans; i++) {
    model_destroy(rt->organs[i].model);
    rt->organs[i].model = NULL;
    aabb_tree_destroy(&rt->organs[i].tree);
    vertex_cull_free(&rt->organs[i].cull);
    free(rt->organs[i].vn_rest);
    rt->organs[i].vn_rest = NULL;
    mesh_free(&rt->organs[i].rest);
    organ_sleep_free(&rt->organs[i].sleep);
  }
  rt->norgans = 0;
}

/* The force limit of the tool's accepted command (tool->cmd; its tip is
 * tool->cmd.pos). */
static void take_pose(runtime_t *rt, tool_rt_t *tool) {
  tool->max_force = fmin(tool->cfg->max_force, tool->cmd.max_force);
  tool->active = 1;
  if (tool->first_cmd_time < 0) tool->first_cmd_time = rt->sim_time;
}

void runtime_command_tool(runtime_t *rt, size_t t, const tool_input_t *in) {
  if (t >= rt->ntools) return;
  tool_rt_t *tool = &rt->tools[t];
  tool->cmd = *in;
  take_pose(rt, tool);
  tool->buttons = in->buttons;
  shaft_axis(in->q, tool->axis);
}

void runtime_set_tool(runtime_t *rt, size_t t, const double pos[3], double device_max_force) {
  if (t >= rt->ntools) return;
  tool_rt_t *tool = &rt->tools[t];
  v3_copy(tool->cmd.pos, pos);
  tool->cmd.max_force = device_max_force;
  take_pose(rt, tool);
}

void runtime_set_buttons(runtime_t *rt, size_t t, uint32_t buttons) {
  if (t >= rt->ntools) return;
  rt->tools[t].cmd.buttons = buttons;
  rt->tools[t].buttons = buttons;
}

void runtime_set_orientation(runtime_t *rt, size_t t, const double q[4]) {
  if (t >= rt->ntools) return;
  memcpy(rt->tools[t].cmd.q, q, sizeof rt->tools[t].cmd.q);
  shaft_axis(q, rt->tools[t].axis);
}

void runtime_release_tool(runtime_t *rt, size_t t) { interact_release_tool(rt, t); }

/* The model's hook, before every sub-step: re-evaluates every proxy spring
 * attached to this organ at the sub-step's surface positions and spreads
 * the reaction -f over the contact patch. */
static void apply_contacts(model_t *m, void *vctx) {
  organ_rt_t *o = vctx;
  runtime_t *rt = o->rt;
  for (size_t t = 0; t < rt->ntools; t++) {
    tool_rt_t *tool = &rt->tools[t];
    proxy_t *p = &tool->proxy;
    if (!tool->active || !p->in_contact || (size_t)p->surface != o->id) continue;
    proxy_follow_surface(p, rt->surfaces, rt->norgans);
    double f[3];
    proxy_spring_force(p, tool->cmd.pos, tool->cfg->stiffness, tool->max_force, f);
    for (size_t j = 0; j < tool->npatch; j++) {
      double fk[3];
      v3_scale(fk, f, -tool->patch_w[j]);
      m->ops->add_surface_force(m, tool->patch[j], fk);
    }
    /* The same spring's stiffness, for a model that takes it implicitly:
     * the patch takes the force, the proxy's triangle carries the
     * attachment point. A clamped spring is as stiff as its clamp allows. */
    if (m->ops->add_surface_coupling && p->tri < m->nsurf_tris) {
      double k = tool->cfg->stiffness, stretch = k * v3_dist(p->pos, tool->cmd.pos);
      if (stretch > tool->max_force) k *= tool->max_force / stretch;
      m->ops->add_surface_coupling(m, k, tool->npatch, tool->patch, tool->patch_w, 3, m->surf_tris + 3 * p->tri,
                                   p->bary);
    }
  }
  interact_apply(rt, o, m);
}

/* Vertex i's turn in the patch (see build_patch): the one test the scan
 * and the culled candidates both run, in ascending vertex order. */
static void patch_consider(tool_rt_t *tool, const double *x, const uint32_t *tri, double r, size_t i) {
  double d = v3_dist(x + 3 * i, tool->proxy.pos);
  int in_tri = i == tri[0] || i == tri[1] || i == tri[2];
  if (d >= r && !in_tri) return;
  double w = d < r ? (1 - d / r) * (1 - d / r) : 0;
  if (in_tri) w = fmax(w, 1e-3);
  size_t slot = tool->npatch;
  if (slot == TOOL_PATCH_MAX) { /* full: replace the lightest if this is heavier */
    size_t lightest = 0;
    for (size_t j = 1; j < TOOL_PATCH_MAX; j++)
      if (tool->patch_w[j] < tool->patch_w[lightest]) lightest = j;
    if (tool->patch_w[lightest] >= w) return;
    slot = lightest;
  } else {
    tool->npatch++;
  }
  tool->patch[slot] = (uint32_t)i;
  tool->patch_w[slot] = w;
}

/* The vertices within the patch radius of the proxy, weighted by a smooth
 * kernel (1 - d/r)^2; the contact triangle's vertices always belong, so a
 * patch is never empty. Keeps the TOOL_PATCH_MAX heaviest if more qualify.
 * The candidates come from the organ's tree (runtime/vertex_cull.h: the
 * tree was refit at the end of the last step, or rebuilt by the topology
 * follow-up just before), plus the contact triangle's corners; every other
 * vertex fails the test, so the patch is the scan's bit for bit. The scan
 * over every vertex stays for what the cull cannot vouch for. */
static void build_patch(runtime_t *rt, tool_rt_t *tool) {
  tool->npatch = 0;
  if (!tool->proxy.in_contact) return;
  organ_rt_t *o = &rt->organs[tool->proxy.surface];
  const model_t *m = o->model;
  double r = fmax(o->patch_radius, 1e-6), sum = 0;
  const uint32_t *tri = m->surf_tris + 3 * tool->proxy.tri;
  size_t nc = SIZE_MAX;
  const uint32_t *cand = NULL;
  if (!rt->cull.force_scan && m->topology_version == o->topology_version &&
      vertex_cull_usable(&o->cull, &o->tree, m->surf_x, m->nsurf, m->nsurf_tris)) {
    vertex_cull_begin(&o->cull);
    double g = r * (1 + VERTEX_CULL_PAD) * rt->cull.patch_scale, lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
      double pad = g + VERTEX_CULL_PAD * 1e-3 * fabs(tool->proxy.pos[k]);
      lo[k] = tool->proxy.pos[k] - pad;
      hi[k] = tool->proxy.pos[k] + pad;
    }
    vertex_cull_box(&o->cull, &o->tree, lo, hi);
    for (int k = 0; k < 3; k++) vertex_cull_add(&o->cull, tri[k]);
    nc = vertex_cull_take(&o->cull, &cand);
  }
  if (nc == SIZE_MAX) {
    rt->cull.patch_scans++;
    for (size_t i = 0; i < m->nsurf; i++) patch_consider(tool, m->surf_x, tri, r, i);
  } else {
    rt->cull.patch_culls++;
    for (size_t j = 0; j < nc; j++) patch_consider(tool, m->surf_x, tri, r, cand[j]);
  }
  for (size_t j = 0; j < tool->npatch; j++) sum += tool->patch_w[j];
  for (size_t j = 0; j < tool->npatch; j++) tool->patch_w[j] /= sum;
}

/* The organ's model changed its topology: fresh tree (its boxes are
 * current), proxies re-attached where they were (anchors), patches from the
 * new vertices, grasps of it released, shading normals of the new surface. */
static void follow_organ(runtime_t *rt, size_t i, const topo_anchor_t anchors[SCENE_MAX_TOOLS]) {
  organ_rt_t *o = &rt->organs[i];
  topo_follow(rt, i, anchors, NULL);
  /* The culls' scratch for the new surface (out of memory: they scan). */
  verr_t e;
  vertex_cull_setup(&o->cull, o->model->nsurf, o->model->surf_tris, o->model->nsurf_tris, &e);
  for (size_t t = 0; t < rt->ntools; t++) {
    if (anchors[t].in_contact) build_patch(rt, &rt->tools[t]);
    /* Held tissue is a list of vertex indices of the old surface: the
     * jaws let go (the trainee closes them again) rather than hold
     * vertices that now mean something else. */
    if (rt->tools[t].grasp.active && rt->tools[t].grasp.organ == (int)o->id) grasp_release(&rt->tools[t].grasp);
  }
  /* Force-shading normals of the new surface (rest shape); if memory
   * runs out shading stays off for this organ (facet normals). */
  double *vn = o->model->nsurf ? realloc(o->vn_rest, 3 * o->model->nsurf * sizeof *vn) : NULL;
  if (vn) {
    o->vn_rest = vn;
    proxy_vertex_normals(o->model->nsurf, o->model->surf_rest, o->model->nsurf_tris, o->model->surf_tris, vn);
    rt->surfaces[i].vn = vn;
    rt->surfaces[i].nvn = o->model->nsurf;
  }
}

void runtime_topology_restored(runtime_t *rt, size_t organ) {
  topo_anchor_t none[SCENE_MAX_TOOLS];
  memset(none, 0, sizeof none);
  for (size_t t = 0; t < SCENE_MAX_TOOLS; t++) none[t].face = UINT32_MAX;
  follow_organ(rt, organ, none);
}

/* 1 when anything could touch organ i in this step: a driven tool's tip or
 * shaft (or the stone it holds) within reach of the organ's current
 * bounding box, its god-object on any surface, a grasp of this organ, a
 * cut under way. The reach adds a margin of max(1 cm, 3 tool radii): a
 * hand moves at most a few mm per ms, so the organ is awake several steps
 * before the tool can arrive. */
static int organ_disturbed(const runtime_t *rt, size_t i) {
  const organ_rt_t *o = &rt->organs[i];
  for (size_t t = 0; t < rt->ntools; t++) {
    const tool_rt_t *tool = &rt->tools[t];
    if (!tool->active) continue;
    if (tool->proxy.in_contact || (tool->grasp.active && tool->grasp.organ == (int)o->id) || scalpel_cutting(rt, t))
      return 1;
    double r = tool->cfg->radius, reach = r + fmax(0.01, 3 * r), end[3];
    v3_copy(end, tool->cmd.pos);
    v3_axpy(end, tool->axis, tool->cfg->length);
    if (organ_sleep_box_near(o->tree.lo, o->tree.hi, tool->cmd.pos, end, reach)) return 1;
    if (tool->stone >= 0) {
      const stone_t *st = &rt->stones[tool->stone];
      if (organ_sleep_box_near(o->tree.lo, o->tree.hi, st->pos, st->pos, st->radius + reach)) return 1;
    }
  }
  return 0;
}

/* Phase contact, before the models: every driven tool that meets tissue
 * moves its god-object toward its tip over the surfaces as they are
 * (friction), and gathers the patch that takes its reaction in the models'
 * hook (apply_contacts). */
static void step_contact(runtime_t *rt) {
  for (size_t t = 0; t < rt->ntools; t++) {
    tool_rt_t *tool = &rt->tools[t];
    if (!tool->active || !interact_uses_proxy(rt, t)) continue;
    proxy_update_friction(&tool->proxy, tool->cmd.pos, rt->surfaces, rt->norgans, tool->cfg->stiffness, tool->max_force,
                          tool->cfg->friction, tool->from.proxy);
    build_patch(rt, tool);
  }
}

/* The surface vertices the model's last step may have moved (model.h
 * last_step_moved), SIZE_MAX when it cannot tell or the runtime asked for
 * full scans (cull.force_scan). */
static size_t last_moved(const runtime_t *rt, const model_t *m, const uint32_t **idx) {
  if (rt->cull.force_scan || !m->ops->last_step_moved) return SIZE_MAX;
  return m->ops->last_step_moved(m, idx);
}

/* Phase topology of organ i: after a cut (or a refinement) changed the
 * model's topology, everything built on its surface follows at once,
 * before anything reads the surface again; otherwise the tree is refit
 * (every step, rolled back or not: the proxy trusts the boxes). */
static void organ_topology(runtime_t *rt, size_t i, const topo_anchor_t anchors[SCENE_MAX_TOOLS]) {
  organ_rt_t *o = &rt->organs[i];
  if (o->model->topology_version != o->topology_version) {
    follow_organ(rt, i, anchors);
  } else if (o->tree.ntris) {
    /* Over the vertices the step may have moved when the model can tell
     * (a pressed organ's still part is most of it); otherwise every one. */
    const uint32_t *moved = NULL;
    size_t nmoved = last_moved(rt, o->model, &moved);
    if (nmoved != SIZE_MAX)
      aabb_tree_refit_listed(&o->tree, o->model->surf_x, moved, nmoved);
    else
      aabb_tree_refit(&o->tree, o->model->surf_x);
  }
}

/* Puts organ i's nodes back at their rest positions with zero velocity
 * (and an embedded surface at its rest embedding); the tree is refit by
 * the topology phase that follows. */
static void organ_to_rest(organ_rt_t *o) {
  model_t *m = o->model;
  if (m->x != m->x_rest) memmove(m->x, m->x_rest, 3 * m->nnodes * sizeof(double));
  memset(m->v, 0, 3 * m->nnodes * sizeof(double));
  if (m->surf_x != m->x && m->surf_x != m->surf_rest) memmove(m->surf_x, m->surf_rest, 3 * m->nsurf * sizeof(double));
  model_note_outside_write(m);
}

/* Phase models: each organ that is not asleep steps its model (the hook
 * applies the tools' contact, grasp, shaft and stone forces every
 * sub-step), then, organ by organ, its cut and the topology follow-up run
 * (phases cut and topology, inside this loop: the next organ's step reads
 * the tools as this organ's follow-up left them). Returns the organs whose
 * step was rolled back. */
static int step_models(runtime_t *rt) {
  double dt = rt->scene.dt;
  /* Stillness over sleep_after, in whole steps (at least 2, scene.c); only
   * worked out when organs may sleep. */
  uint32_t need = rt->scene.sleep_speed > 0 ? (uint32_t)fmin(4e9, ceil(rt->scene.sleep_after / dt - 1e-9)) : 0;
  int rolled = 0;
  for (size_t i = 0; i < rt->norgans; i++) {
    organ_rt_t *o = &rt->organs[i];
    int sleeping = rt->scene.sleep_speed > 0, disturbed = 0;
    if (sleeping) {
      disturbed = organ_disturbed(rt, i);
      if (o->sleep.asleep) {
        if (!disturbed) {
          o->sleep.slept_steps++;
          continue; /* nothing moves it: no step, no refit (the boxes still fit) */
        }
        organ_sleep_wake(&o->sleep);
      }
    }
    rt->organs_stepped++;
    topo_anchor_t anchors[SCENE_MAX_TOOLS];
    topo_capture(rt, i, anchors);
    uint32_t topo = o->topology_version;
    int bad = o->model->ops->step(o->model, dt) < 0;
    if (bad) {
      o->rollbacks++;
      rolled++;
      if (++o->rollback_run >= RUNTIME_ROLLBACK_RESET) {
        organ_to_rest(o);
        o->rest_resets++;
        o->rollback_run = 0;
        rt->organs_reset |= 1u << i;
      }
    } else {
      o->rollback_run = 0;
    }
    scalpel_after_organ_step(rt, i); /* phase cut: may change the topology */
    organ_topology(rt, i, anchors);  /* phase topology */
    /* A rolled-back or re-meshed step is no evidence of rest. */
    if (sleeping) {
      const uint32_t *moved = NULL;
      size_t nmoved = o->topology_version == topo ? last_moved(rt, o->model, &moved) : SIZE_MAX;
      organ_sleep_observe_listed(&o->sleep, o->model->surf_x, o->model->nsurf, nmoved == SIZE_MAX ? NULL : moved,
                                 nmoved, rt->scene.sleep_speed * dt, need,
                                 disturbed || bad || o->topology_version != topo);
    }
  }
  return rolled;
}

/* Phase contact, after the models: the god-objects settle on the moved
 * surfaces; their spring is the proxy's contribution to the hand force
 * (tool->from.proxy). */
static void settle_tool(const runtime_t *rt, tool_rt_t *tool) {
  if (!tool->active) return;
  proxy_settle(&tool->proxy, rt->scene.dt);
  proxy_follow_surface(&tool->proxy, rt->surfaces, rt->norgans);
  tool->from.proxy_mag =
      proxy_spring_force(&tool->proxy, tool->cmd.pos, tool->cfg->stiffness, tool->max_force, tool->from.proxy);
}

static void settle_contact(runtime_t *rt) {
  for (size_t t = 0; t < rt->ntools; t++) settle_tool(rt, &rt->tools[t]);
}

/* The phases in order: inputs (the accepted commands' jaws), tools (grasp,
 * release, carry), contact (god-objects onto the surfaces) = begin; models
 * (organ steps, each followed by its cut and topology follow-up), contact
 * again (settle, proxy spring), outputs (hand force, feedback, events,
 * tasks) = finish. Between the two the preview may run: it settles copies
 * of the tool records on the surfaces as they are (settle_tool, the
 * settle phase's own code) and runs the outputs' feedback part
 * (interact_feedback) on those copies, never on rt's state (only the
 * culls' working memory). */
void runtime_step_begin(runtime_t *rt) {
  rt->organs_stepped = 0;
  rt->organs_reset = 0;
  interact_inputs(rt);
  interact_tools(rt);
  step_contact(rt);
}

void runtime_feedback_preview(runtime_t *rt, tool_rt_t tools[SCENE_MAX_TOOLS]) {
  memcpy(tools, rt->tools, rt->ntools * sizeof *tools);
  for (size_t t = 0; t < rt->ntools; t++) settle_tool(rt, &tools[t]);
  interact_feedback(rt, tools);
}

int runtime_step_finish(runtime_t *rt) {
  int rolled = step_models(rt);
  settle_contact(rt);
  rt->steps++;
  rt->sim_time = (double)rt->steps * rt->scene.dt;
  interact_outputs(rt);
  return rolled;
}

int runtime_step(runtime_t *rt) {
  runtime_step_begin(rt);
  return runtime_step_finish(rt);
}
