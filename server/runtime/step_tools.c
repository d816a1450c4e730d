/* SPDX-License-Identifier: Apache-2.0 */
#include "runtime/step_tools.h"

#include <math.h>
#include <string.h>

#include "interaction/shaft.h"
#include "runtime/step_cut.h"
#include "vmath.h"

/* The removal test scans the organ's rest surface (O(triangles)): every
 * STONE_CHECK_EVERY steps while a stone is held is plenty for a hand. */
#define STONE_CHECK_EVERY 20

static int is_kind(const tool_rt_t *tool, const char *kind) { return !strcmp(tool->cfg->kind, kind); }

static void push_event(runtime_t *rt, iev_kind_t kind, int tool, int organ, int object, double value) {
  iev_push(&rt->events, (iev_t){.kind = kind,
                                .tool = tool,
                                .organ = organ,
                                .object = object,
                                .task = -1,
                                .value = value,
                                .sim_time = rt->sim_time});
}

int interact_init(runtime_t *rt, verr_t *err) {
  const scene_t *sc = &rt->scene;
  rt->nstones = sc->nobjects;
  for (size_t i = 0; i < sc->nobjects; i++) {
    const scene_object_t *ob = &sc->objects[i];
    stone_init(&rt->stones[i], ob->radius, ob->organ, ob->position);
    const model_t *m = rt->organs[ob->organ].model;
    double wn = stone_winding_number(m->surf_rest, m->surf_tris, m->nsurf_tris, ob->position);
    if (!(wn > 0.5))
      return verr_set(err, "%s:%d: object '%s': centre [%g, %g, %g] is not inside organ '%s' (winding number %.2f)",
                      sc->path, ob->line, ob->name, ob->position[0], ob->position[1], ob->position[2],
                      sc->organs[ob->organ].name, wn);
  }
  for (size_t t = 0; t < rt->ntools; t++) {
    grasp_init(&rt->tools[t].grasp);
    rt->tools[t].stone = -1;
    rt->tools[t].first_cmd_time = -1;
    v3_set(rt->tools[t].axis, 0, 0, 1);
  }
  rt->ntasks = sc->ntasks;
  tasks_init(rt->tasks, sc);
  return 0;
}

int interact_uses_proxy(const runtime_t *rt, size_t t) {
  const tool_rt_t *tool = &rt->tools[t];
  /* A cutting scalpel's blade goes into the tissue (runtime/step_cut.h). */
  return !is_kind(tool, "extractor") && !tool->grasp.active && !scalpel_cutting(rt, t);
}

/* Grasper closing: the organ with a surface vertex nearest the tip. */
static void try_grasp_tissue(runtime_t *rt, size_t t) {
  tool_rt_t *tool = &rt->tools[t];
  int best = -1;
  double best_d = INFINITY;
  for (size_t i = 0; i < rt->norgans; i++) {
    const model_t *m = rt->organs[i].model;
    for (size_t v = 0; v < m->nsurf; v++) {
      double d = v3_dist(m->surf_x + 3 * v, tool->cmd.pos);
      if (d < best_d) {
        best_d = d;
        best = (int)i;
      }
    }
  }
  if (best < 0 || best_d > tool->cfg->grasp_radius) return;
  const model_t *m = rt->organs[best].model;
  size_t n = grasp_take(&tool->grasp, best, m->surf_x, m->nsurf, tool->cmd.pos, tool->cfg->grasp_radius);
  if (n) push_event(rt, IEV_GRASP_BEGIN, (int)t, best, -1, (double)n);
}

/* Extractor closing: the nearest free stone within reach. */
static void try_grasp_stone(runtime_t *rt, size_t t) {
  tool_rt_t *tool = &rt->tools[t];
  int best = -1;
  double best_d = INFINITY;
  for (size_t i = 0; i < rt->nstones; i++) {
    const stone_t *s = &rt->stones[i];
    double d = v3_dist(s->pos, tool->cmd.pos) - s->radius;
    if (s->held_by < 0 && stone_within_reach(s, tool->cmd.pos, tool->cfg->grasp_radius) && d < best_d) {
      best_d = d;
      best = (int)i;
    }
  }
  if (best < 0) return;
  stone_grab(&rt->stones[best], (int)t, tool->cmd.pos);
  tool->stone = best;
  push_event(rt, IEV_GRASP_BEGIN, (int)t, -1, best, 1);
}

static void release_held(runtime_t *rt, size_t t) {
  tool_rt_t *tool = &rt->tools[t];
  if (tool->grasp.active) {
    int organ = tool->grasp.organ;
    grasp_release(&tool->grasp);
    push_event(rt, IEV_GRASP_END, (int)t, organ, -1, 0);
  }
  if (tool->stone >= 0) {
    stone_t *s = &rt->stones[tool->stone];
    stone_release(s);
    /* Where it was let go decides removal: check now, not in 20 steps. */
    const model_t *m = rt->organs[s->organ].model;
    stone_check_removed(s, m->surf_rest, m->surf_tris, m->nsurf_tris);
    push_event(rt, IEV_GRASP_END, (int)t, -1, tool->stone, 0);
    tool->stone = -1;
  }
}

void interact_release_tool(runtime_t *rt, size_t t) {
  if (t >= rt->ntools) return;
  tool_rt_t *tool = &rt->tools[t];
  release_held(rt, t);
  tool->buttons = tool->prev_buttons = 0;
  tool->fb_contact = 0;
  tool->active = 0;
  /* The proxy keeps its contact: a client that drops out for a moment (a
   * stall, a link blip, a false "client lost") comes back to the same
   * scene, so a hand still inside the organ is pushed out again rather
   * than left inside with no entry crossing to find (docs/remote.md).
   * A hand that comes back elsewhere releases it at the first update. */
  interact_hand_force(rt, t);
}

void interact_inputs(runtime_t *rt) {
  for (size_t t = 0; t < rt->ntools; t++) {
    tool_rt_t *tool = &rt->tools[t];
    if (!tool->active) continue;
    int closed = (tool->buttons & 1u) != 0, was = (tool->prev_buttons & 1u) != 0;
    tool->prev_buttons = tool->buttons;
    tool->closing = closed && !was;
    tool->opening = !closed && was;
  }
}

void interact_tools(runtime_t *rt) {
  for (size_t t = 0; t < rt->ntools; t++) {
    tool_rt_t *tool = &rt->tools[t];
    if (!tool->active) continue;
    if (tool->closing) {
      if (is_kind(tool, "grasper")) try_grasp_tissue(rt, t);
      if (is_kind(tool, "extractor")) try_grasp_stone(rt, t);
    } else if (tool->opening) {
      release_held(rt, t);
    }
    if (tool->stone >= 0) stone_follow(&rt->stones[tool->stone], tool->cmd.pos);
    if (!interact_uses_proxy(rt, t)) {
      proxy_reset(&tool->proxy);
      tool->npatch = 0;
    }
  }
}

/* The shaft of a driven tool that meets tissue (not the extractor: it
 * enters through its port); its tip is where the hand's tip is held. */
static int shaft_of(const runtime_t *rt, const tool_rt_t *tool, size_t t, double p0[3], double p1[3]) {
  /* A cutting scalpel parts the tissue instead of pushing it (runtime/step_cut.h). */
  if (!tool->active || is_kind(tool, "extractor") || scalpel_cutting(rt, t)) return 0;
  const double *tip = tool->proxy.in_contact ? tool->proxy.pos : tool->cmd.pos;
  shaft_segment(tip, tool->axis, tool->cfg->radius, tool->cfg->length, p0, p1);
  return 1;
}

/* 1 when tool's god-object is in contact with organ `organ`. */
static int tip_on(const tool_rt_t *tool, size_t organ) {
  return tool->proxy.in_contact && tool->proxy.surface >= 0 && (size_t)tool->proxy.surface == organ;
}

/* A penalty spring of stiffness k on one vertex: its force, and its
 * stiffness for a model that takes tool springs implicitly (model.h). */
typedef struct spring_ctx {
  model_t *m;
  double k;
} spring_ctx_t;

static void declare_spring(model_t *m, uint32_t i, double k) {
  static const double one = 1;
  if (m->ops->add_surface_coupling) m->ops->add_surface_coupling(m, k, 1, &i, &one, 1, &i, &one);
}

static void add_spring_force(void *ctx, uint32_t i, const double f[3]) {
  spring_ctx_t *sc = ctx;
  sc->m->ops->add_surface_force(sc->m, i, f);
  declare_spring(sc->m, i, sc->k);
}

/* The shaft's node test over the candidates of organ o's tree
 * (runtime/vertex_cull.h) instead of every vertex: the tree fits the
 * positions it was refit to at the end of the last step, which the
 * surface still has after the step (in_step 0: the runtime refit or
 * rebuilt it) or, inside the step (the model's hook), for every vertex
 * but those the model says may have moved since the step began
 * (model.h surface_moved), which join the candidates. Sets s->cand, or
 * leaves it NULL (scan every vertex) when the model cannot tell, more
 * than a quarter of the surface moved, the tree is another surface's or
 * the shaft is not a number. */
static void shaft_candidates(runtime_t *rt, organ_rt_t *o, const double p0[3], const double p1[3], double radius,
                             int in_step, shaft_surface_t *s) {
  const model_t *m = o->model;
  s->cand = NULL;
  if (rt->cull.force_scan || m->topology_version != o->topology_version ||
      !vertex_cull_usable(&o->cull, &o->tree, m->surf_x, m->nsurf, m->nsurf_tris)) {
    rt->cull.shaft_scans++;
    return;
  }
  const uint32_t *moved = NULL;
  size_t nmoved = 0;
  if (in_step) {
    nmoved = m->ops->surface_moved ? m->ops->surface_moved(m, &moved) : SIZE_MAX;
    /* Most of the organ moving: the scan is as cheap. */
    if (nmoved > m->nsurf / 4) {
      rt->cull.shaft_scans++;
      return;
    }
  }
  const uint32_t *cand;
  size_t n = vertex_cull_segment(&o->cull, &o->tree, p0, p1, radius * rt->cull.shaft_scale, moved, nmoved, &cand);
  if (n == SIZE_MAX) {
    rt->cull.shaft_scans++;
    return;
  }
  rt->cull.shaft_culls++;
  s->cand = cand;
  s->ncand = n;
}

void interact_apply(runtime_t *rt, organ_rt_t *o, model_t *m) {
  for (size_t t = 0; t < rt->ntools; t++) {
    tool_rt_t *tool = &rt->tools[t];
    if (!tool->active || !tool->grasp.active || tool->grasp.organ != (int)o->id) continue;
    /* Held vertex indices belong to the surface they were taken from; a
     * topology change (refinement, a cut) renumbers it, and the runtime
     * lets go then. Never index past the current surface meanwhile. */
    int stale = 0;
    for (size_t j = 0; j < tool->grasp.n; j++) stale |= tool->grasp.v[j] >= m->nsurf;
    if (stale) {
      grasp_release(&tool->grasp);
      continue;
    }
    double fv[GRASP_MAX_VERTS][3], ft[3];
    grasp_force(&tool->grasp, m->surf_x, tool->cmd.pos, tool->cfg->stiffness, tool->max_force, fv, ft);
    for (size_t j = 0; j < tool->grasp.n; j++) {
      m->ops->add_surface_force(m, tool->grasp.v[j], fv[j]);
      declare_spring(m, tool->grasp.v[j], tool->cfg->stiffness * tool->grasp.w[j]);
    }
  }
  /* The shafts' crossing test reads the organ's tree as refit at the start
   * of the step, so the surface may have moved since: the slack (shaft.h)
   * covers a shaft radius of it. After a topology change inside the step
   * the tree is the old surface's: scan instead. */
  const aabb_tree_t *tree = o->tree.ntris && m->topology_version == o->topology_version ? &o->tree : NULL;
  for (size_t t = 0; t < rt->ntools; t++) {
    tool_rt_t *tool = &rt->tools[t];
    double p0[3], p1[3], ft[3] = {0, 0, 0};
    if (!shaft_of(rt, tool, t, p0, p1)) continue;
    double radius = SHAFT_RADIUS_FRACTION * tool->cfg->radius;
    spring_ctx_t sc = {m, tool->cfg->stiffness};
    shaft_surface_t surf = {m->surf_x, m->nsurf, m->surf_tris, m->nsurf_tris, tree, radius, NULL, 0};
    shaft_candidates(rt, o, p0, p1, radius, 1, &surf);
    if (tip_on(tool, o->id)) {
      /* The tip presses this organ: the shaft rises out of the tip's own dent,
       * whose walls its axis can graze when the dent is deep; pushing those
       * triangles aside would open the dent under the god-object (stability
       * case 9 lost its contact that way). Only the node test here. */
      if (surf.cand)
        shaft_push_list(p0, p1, radius, tool->cfg->stiffness, m->surf_x, surf.cand, surf.ncand, add_spring_force, &sc,
                        ft);
      else
        shaft_push(p0, p1, radius, tool->cfg->stiffness, m->surf_x, m->nsurf, add_spring_force, &sc, ft);
      continue;
    }
    shaft_contact(p0, p1, radius, tool->cfg->stiffness, &surf, add_spring_force, &sc, ft, NULL);
  }
  for (size_t i = 0; i < rt->nstones; i++) {
    stone_t *s = &rt->stones[i];
    if (s->organ != (int)o->id) continue;
    double k = s->held_by >= 0 ? rt->tools[s->held_by].cfg->stiffness : STONE_REST_STIFFNESS;
    spring_ctx_t sc = {m, k};
    stone_push(s, m->surf_x, m->nsurf, k, add_spring_force, &sc);
  }
}

/* f clamped to the tool's force limit. */
static void clamp_force(const tool_rt_t *tool, const double in[3], double f[3]) {
  v3_copy(f, in);
  double mag = v3_norm(f);
  if (mag > tool->max_force && mag > 0) v3_scale(f, f, tool->max_force / mag);
}

/* A pull f (already clamped) on the tool: the client is told a contact
 * plane through device + f / k with normal f / |f|, which renders f at the
 * device. */
static void tell_pulled(tool_rt_t *tool, const double f[3], int organ) {
  tool->fb_contact = 1;
  tool->fb_organ = organ;
  v3_copy(tool->fb_normal, f);
  if (v3_normalize(tool->fb_normal) <= 0) v3_set(tool->fb_normal, 0, 0, 1);
  v3_copy(tool->fb_pos, tool->cmd.pos);
  v3_axpy(tool->fb_pos, f, 1.0 / tool->cfg->stiffness);
}

static void add_nothing(void *ctx, uint32_t i, const double f[3]) {
  (void)ctx;
  (void)i;
  (void)f;
}

/* The shaft's reaction at the end of the step (from->shaft): added to
 * what the tip feels; a shaft touching while the tip is free is a contact
 * of its own. */
static void shaft_contribution(runtime_t *rt, tool_rt_t *tool, size_t t) {
  tool_forces_t *from = &tool->from;
  double p0[3], p1[3];
  v3_set(from->shaft, 0, 0, 0);
  if (!shaft_of(rt, tool, t, p0, p1)) return;
  double radius = SHAFT_RADIUS_FRACTION * tool->cfg->radius;
  for (size_t i = 0; i < rt->norgans; i++) {
    organ_rt_t *o = &rt->organs[i];
    const model_t *m = o->model;
    /* After the step the runtime has refit (or rebuilt) the tree. */
    shaft_surface_t surf = {m->surf_x,
                            m->nsurf,
                            m->surf_tris,
                            m->nsurf_tris,
                            o->tree.ntris && m->topology_version == o->topology_version ? &o->tree : NULL,
                            0,
                            NULL,
                            0};
    /* Writes only the culls' scratch and counters (working memory, not
     * state of the step): a preview may run it. */
    shaft_candidates(rt, o, p0, p1, radius, 0, &surf);
    size_t h = tip_on(tool, i)
                   ? (surf.cand ? shaft_push_list(p0, p1, radius, tool->cfg->stiffness, m->surf_x, surf.cand,
                                                  surf.ncand, add_nothing, NULL, from->shaft)
                                : shaft_push(p0, p1, radius, tool->cfg->stiffness, m->surf_x, m->nsurf, add_nothing,
                                             NULL, from->shaft))
                   : shaft_contact(p0, p1, radius, tool->cfg->stiffness, &surf, add_nothing, NULL, from->shaft, NULL);
    if (h && from->shaft_organ < 0) from->shaft_organ = (int)i;
    from->shaft_hits += h;
  }
}

/* The extractor's tip against a stone it does not hold: a god-object on
 * the sphere of radius stone + tip (from->touch). */
static void stone_touch(const runtime_t *rt, tool_rt_t *tool) {
  tool_forces_t *from = &tool->from;
  for (size_t i = 0; i < rt->nstones; i++) {
    const stone_t *s = &rt->stones[i];
    double d[3], reach = s->radius + tool->cfg->radius;
    v3_sub(d, tool->cmd.pos, s->pos);
    double len = v3_norm(d);
    if (!(len < reach) || len < 1e-12) continue;
    v3_copy(from->touch_p, s->pos);
    v3_axpy(from->touch_p, d, reach / len);
    v3_sub(from->touch_f, from->touch_p, tool->cmd.pos);
    v3_scale(from->touch_f, from->touch_f, tool->cfg->stiffness);
    v3_scale(from->touch_n, d, 1 / len);
    from->touch = 1;
    return;
  }
}

/* What the outputs phase adds to tool t's contributions: the grasp's pull
 * or the held stone's reaction, an extractor's touch of a free stone, the
 * shaft's reaction. */
static void contributions(runtime_t *rt, tool_rt_t *tool, size_t t) {
  tool_forces_t *from = &tool->from;
  from->pull = from->touch = from->tool_tool = 0;
  from->pull_organ = from->shaft_organ = -1;
  from->shaft_hits = 0;
  if (!tool->active) return;
  if (tool->grasp.active) {
    const model_t *m = rt->organs[tool->grasp.organ].model;
    double fv[GRASP_MAX_VERTS][3];
    grasp_force(&tool->grasp, m->surf_x, tool->cmd.pos, tool->cfg->stiffness, tool->max_force, fv, from->pull_f);
    from->pull = 1;
    from->pull_organ = tool->grasp.organ;
  } else if (tool->stone >= 0) {
    v3_copy(from->pull_f, rt->stones[tool->stone].force);
    from->pull = 1;
  } else if (is_kind(tool, "extractor")) {
    stone_touch(rt, tool);
  }
  shaft_contribution(rt, tool, t);
}

/* The tip's force before other tools push it: the grasp pull or held
 * stone (clamped), an extractor's stone touch (clamped) or the proxy
 * spring, plus the shaft's reaction (the sum clamped). */
static void tip_force(const tool_rt_t *tool, double f[3]) {
  const tool_forces_t *from = &tool->from;
  if (from->pull)
    clamp_force(tool, from->pull_f, f);
  else if (is_kind(tool, "extractor") && from->touch)
    clamp_force(tool, from->touch_f, f);
  else if (is_kind(tool, "extractor"))
    v3_set(f, 0, 0, 0);
  else
    v3_copy(f, from->proxy);
  if (from->shaft_hits) {
    double sum[3];
    v3_add(sum, f, from->shaft);
    clamp_force(tool, sum, f);
  }
}

/* What tool t's client is told about its tip: a pull's plane, the stone
 * the extractor touches, or the god-object; a shaft touching while the tip
 * is free is told as a pull of its own. */
static void tip_feedback(tool_rt_t *tool) {
  const tool_forces_t *from = &tool->from;
  tool->fb_contact = 0;
  tool->fb_organ = -1;
  if (!tool->active) return;
  if (from->pull) {
    double f[3];
    clamp_force(tool, from->pull_f, f);
    tell_pulled(tool, f, from->pull_organ);
  } else if (is_kind(tool, "extractor")) {
    v3_copy(tool->fb_pos, tool->cmd.pos);
    v3_set(tool->fb_normal, 0, 0, 1);
    if (from->touch) {
      tool->fb_contact = 1;
      v3_copy(tool->fb_pos, from->touch_p);
      v3_copy(tool->fb_normal, from->touch_n);
    }
  } else {
    tool->fb_contact = tool->proxy.in_contact;
    tool->fb_organ = tool->proxy.in_contact ? tool->proxy.surface : -1;
    v3_copy(tool->fb_pos, tool->proxy.pos);
    v3_copy(tool->fb_normal, tool->proxy.normal);
  }
  if (from->shaft_hits && !tool->fb_contact) {
    double f[3];
    tip_force(tool, f);
    tell_pulled(tool, f, from->shaft_organ);
  }
}

/* Keeps every pair of tips at least r_i + r_j apart: each of the two moves
 * half the overlap along the line between them (a few Gauss-Seidel passes
 * for three or more tools in a cluster). A moved tip is a contact
 * (from->tool_tool): the tool feels K (tip - device), clamped. */
static void tool_tool_contact(tool_rt_t *tools, size_t ntools) {
  for (int pass = 0; pass < 4; pass++) {
    int any = 0;
    for (size_t a = 0; a < ntools; a++)
      for (size_t b = a + 1; b < ntools; b++) {
        tool_rt_t *ta = &tools[a], *tb = &tools[b];
        if (!ta->active || !tb->active) continue;
        double d[3], need = ta->cfg->radius + tb->cfg->radius;
        v3_sub(d, ta->fb_pos, tb->fb_pos);
        double len = v3_norm(d);
        if (len >= need) continue;
        if (len < 1e-12) v3_set(d, 0, 0, 1), len = 1; /* coincident: any direction */
        double push = 0.5 * (need - len) * (1 + 1e-9), n[3];
        v3_scale(n, d, 1 / len);
        v3_axpy(ta->fb_pos, n, push);
        v3_axpy(tb->fb_pos, n, -push);
        ta->from.tool_tool = tb->from.tool_tool = 1;
        any = 1;
      }
    if (!any) break;
  }
}

/* The one function that writes a tool record's force (tool->force):
 * interact_hand_force on the runtime's record, interact_feedback on the
 * preview's copies (runtime_feedback_preview). */
static void hand_force(tool_rt_t *tool) {
  const tool_forces_t *from = &tool->from;
  if (!tool->active) {
    v3_set(tool->force, 0, 0, 0);
    return;
  }
  double f[3];
  if (from->tool_tool) {
    v3_sub(f, tool->fb_pos, tool->cmd.pos);
    v3_scale(f, f, tool->cfg->stiffness);
    double mag = v3_norm(f);
    if (mag > tool->max_force) v3_scale(f, f, tool->max_force / mag);
  } else {
    tip_force(tool, f);
  }
  v3_copy(tool->force, f);
  if (from->proxy_mag > tool->peak_force) tool->peak_force = from->proxy_mag;
  double mag = v3_norm(tool->force);
  if (mag > tool->peak_force) tool->peak_force = mag;
}

void interact_hand_force(runtime_t *rt, size_t t) { hand_force(&rt->tools[t]); }

/* A tip another tool moved is a contact: with another tool (organ -1, the
 * force's direction) unless the god-object still touches an organ. */
static void tool_tool_feedback(tool_rt_t *tool) {
  tool->fb_contact = 1;
  if (tool->fb_organ < 0 || !tool->proxy.in_contact) {
    tool->fb_organ = -1;
    v3_copy(tool->fb_normal, tool->force);
    if (v3_normalize(tool->fb_normal) <= 0) v3_set(tool->fb_normal, 0, 0, 1);
  }
}

void interact_feedback(runtime_t *rt, tool_rt_t *tools) {
  for (size_t t = 0; t < rt->ntools; t++) {
    contributions(rt, &tools[t], t);
    tip_feedback(&tools[t]);
  }
  tool_tool_contact(tools, rt->ntools);
  for (size_t t = 0; t < rt->ntools; t++) {
    hand_force(&tools[t]);
    if (tools[t].active && tools[t].from.tool_tool) tool_tool_feedback(&tools[t]);
  }
}

void interact_outputs(runtime_t *rt) {
  interact_feedback(rt, rt->tools);
  for (size_t i = 0; i < rt->nstones; i++) {
    stone_t *s = &rt->stones[i];
    if (s->held_by < 0 || s->removed || rt->steps % STONE_CHECK_EVERY) continue;
    const model_t *m = rt->organs[s->organ].model;
    stone_check_removed(s, m->surf_rest, m->surf_tris, m->nsurf_tris);
  }
  task_tool_view_t views[SCENE_MAX_TOOLS];
  for (size_t t = 0; t < rt->ntools; t++) {
    const tool_rt_t *tool = &rt->tools[t];
    views[t] = (task_tool_view_t){.active = tool->active,
                                  .first_cmd_time = tool->first_cmd_time,
                                  .fb_contact = tool->fb_contact,
                                  .fb_organ = tool->fb_organ,
                                  .fb_pos = tool->fb_pos,
                                  .device = tool->cmd.pos,
                                  .grasp = &tool->grasp};
  }
  tasks_update(rt->tasks, rt->ntasks, views, rt->stones, rt->sim_time, &rt->events);
}
