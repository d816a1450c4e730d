/* SPDX-License-Identifier: Apache-2.0 */
#include "runtime/step_cut.h"

#include <inttypes.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cutting/ms_cut.h"
#include "cutting/tet_model_cut.h"
#include "vmath.h"
#include "vtime.h"

/* Any radius the ms cutter accepts: the parked blade touches nothing. */
#define PARKED_RADIUS 1e-3

typedef struct scalpel_organ {
  ms_cut_t *ms;         /* mass_spring_surface organ (model.h edit kind SURFACE) */
  tet_model_cut_t *tet; /* pbd/xpbd organ (edit kind TETS), mesh copied at load */
  int tool;             /* scalpel cutting it now, -1 */
  int touched;          /* the current cut touched tissue (IEV_CUT_BEGIN sent) */
  size_t edges0;        /* pbd: cutter's cut edges when the current cut started */
  uint64_t changes0;
  scalpel_organ_stats_t st;
} scalpel_organ_t;

struct scalpel {
  scalpel_organ_t organ[SCENE_MAX_ORGANS];
  double parked[3]; /* outside every organ: the ms cutters' blade while nobody cuts */
  uint64_t refused, refused_taken;
  char last_error[240];
};

static int is_scalpel(const tool_rt_t *tool) { return !strcmp(tool->cfg->kind, "scalpel"); }

int scalpel_init(runtime_t *rt, verr_t *err) {
  const scene_t *sc = &rt->scene;
  int any = 0;
  double radius = 0;
  int radius_line = 0;
  for (size_t t = 0; t < rt->ntools; t++)
    if (is_scalpel(&rt->tools[t])) {
      any = 1;
      if (rt->tools[t].cfg->radius > radius) {
        radius = rt->tools[t].cfg->radius;
        radius_line = rt->tools[t].cfg->line;
      }
    }
  if (!any) return 0;
  struct scalpel *s = calloc(1, sizeof *s);
  if (!s) return verr_set(err, "%s: out of memory for the scalpel", sc->path);
  rt->scalpel = s;
  /* The workspace reaches at least 1 m beyond every organ's rest bounds:
   * its corner is outside any organ however it deforms. */
  v3_copy(s->parked, rt->workspace.max);
  for (size_t i = 0; i < rt->norgans; i++) {
    scalpel_organ_t *so = &s->organ[i];
    organ_rt_t *o = &rt->organs[i];
    so->tool = -1;
    so->st.nsurf_initial = o->model->nsurf;
    verr_t e;
    const model_edit_ops_t *edit = o->model->ops->edit;
    if (edit && edit->kind == MODEL_EDIT_TETS) {
      so->tet = tet_model_cut_create(o->model, &e);
      if (!so->tet || tet_model_cut_prepare(so->tet, &e))
        return verr_set(err, "%s:%d: organ '%s': scalpel: %s", sc->path, o->cfg->line, o->cfg->name, e.msg);
    } else if (edit && edit->kind == MODEL_EDIT_SURFACE) {
      ms_cut_params_t p = ms_cut_default_params();
      if (radius > p.max_radius)
        return verr_set(err,
                        "%s:%d: scalpel radius %g m: a mass_spring_surface organ ('%s') is cut with a blade of "
                        "at most %g m radius",
                        sc->path, radius_line, radius, o->cfg->name, p.max_radius);
      so->ms = ms_cut_create(o->model, &p, &e);
      if (!so->ms) return verr_set(err, "%s:%d: organ '%s': scalpel: %s", sc->path, o->cfg->line, o->cfg->name, e.msg);
    }
    so->st.can_cut = so->tet || so->ms;
  }
  return 0;
}

void scalpel_destroy(runtime_t *rt) {
  struct scalpel *s = rt->scalpel;
  if (!s) return;
  /* Before the models: a cutter refers to its model. */
  for (size_t i = 0; i < SCENE_MAX_ORGANS; i++) {
    ms_cut_destroy(s->organ[i].ms);
    tet_model_cut_destroy(s->organ[i].tet);
  }
  free(s);
  rt->scalpel = NULL;
}

int scalpel_cutting(const runtime_t *rt, size_t t) {
  if (!rt->scalpel || t >= rt->ntools) return 0;
  const tool_rt_t *tool = &rt->tools[t];
  return tool->active && is_scalpel(tool) && (tool->buttons & 1u);
}

/* Tip = the commanded position, handle = tip + blade_length along the axis. */
static void blade(const tool_rt_t *tool, double tip[3], double handle[3]) {
  v3_copy(tip, tool->cmd.pos);
  v3_copy(handle, tool->cmd.pos);
  v3_axpy(handle, tool->axis, tool->cfg->blade_length);
}

/* Whether the blade's box meets the organ's current surface bounds grown by
 * `margin`: the cheap "the blade reaches this organ" test. */
static int blade_reaches(const model_t *m, const double tip[3], const double handle[3], double margin) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t v = 0; v < m->nsurf; v++)
    for (int k = 0; k < 3; k++) {
      lo[k] = fmin(lo[k], m->surf_x[3 * v + k]);
      hi[k] = fmax(hi[k], m->surf_x[3 * v + k]);
    }
  for (int k = 0; k < 3; k++)
    if (fmax(tip[k], handle[k]) < lo[k] - margin || fmin(tip[k], handle[k]) > hi[k] + margin) return 0;
  return 1;
}

static void push(runtime_t *rt, iev_kind_t kind, int tool, size_t organ, double value) {
  iev_push(&rt->events, (iev_t){.kind = kind,
                                .tool = tool,
                                .organ = (int)organ,
                                .object = -1,
                                .task = -1,
                                .value = value,
                                .sim_time = rt->sim_time});
}

static void refused(struct scalpel *s, const organ_rt_t *o, const char *msg) {
  s->organ[o->id].st.refused++;
  s->refused++;
  /* Precision-bounded: the log line stays short whatever the cutter says. */
  snprintf(s->last_error, sizeof s->last_error, "organ '%.63s': cut refused: %.100s", o->cfg->name, msg);
}

/* Book-keeping of one cutter call: time, topology change, refusal. */
static void account(struct scalpel *s, organ_rt_t *o, uint32_t version0, uint64_t t0, int rc, const verr_t *e) {
  scalpel_organ_t *so = &s->organ[o->id];
  const model_t *m = o->model;
  double us = (double)(vtime_mono_ns() - t0) * 1e-3;
  so->st.calls++;
  so->st.call_us_sum += us;
  so->st.call_us_max = fmax(so->st.call_us_max, us);
  if (m->topology_version != version0) {
    so->st.topology_changes++;
    so->st.change_calls++;
    so->st.change_us_sum += us;
    so->st.change_us_max = fmax(so->st.change_us_max, us);
    size_t kb = m->nsurf * 3 * sizeof(float) + m->nsurf_tris * 3 * sizeof(uint32_t);
    if (kb > so->st.max_keyframe_bytes) so->st.max_keyframe_bytes = kb;
  }
  if (rc < 0) refused(s, o, e->msg);
}

static void cut_begin_if_touched(runtime_t *rt, scalpel_organ_t *so, size_t organ, int touching) {
  if (so->touched || !touching) return;
  so->touched = 1;
  so->st.cuts++;
  so->changes0 = so->st.topology_changes;
  push(rt, IEV_CUT_BEGIN, so->tool, organ, (double)rt->organs[organ].model->nsurf);
}

static void cut_finished(runtime_t *rt, scalpel_organ_t *so, size_t organ) {
  if (so->touched) push(rt, IEV_CUT_END, so->tool, organ, (double)(so->st.topology_changes - so->changes0));
  so->touched = 0;
  so->tool = -1;
}

/* The first cutting scalpel whose blade reaches the organ, or -1. */
static int cutter_for(const runtime_t *rt, const model_t *m, int current) {
  if (current >= 0 && scalpel_cutting(rt, (size_t)current)) return current; /* keeps its organ while pressed */
  for (size_t t = 0; t < rt->ntools; t++) {
    if (!scalpel_cutting(rt, t)) continue;
    double tip[3], handle[3];
    blade(&rt->tools[t], tip, handle);
    if (blade_reaches(m, tip, handle, rt->tools[t].cfg->radius)) return (int)t;
  }
  return -1;
}

static void step_tet(runtime_t *rt, struct scalpel *s, size_t organ) {
  scalpel_organ_t *so = &s->organ[organ];
  organ_rt_t *o = &rt->organs[organ];
  model_t *m = o->model;
  int t = cutter_for(rt, m, so->tool);
  double tip[3], handle[3];
  int in = 0;
  if (t >= 0) {
    blade(&rt->tools[t], tip, handle);
    in = blade_reaches(m, tip, handle, rt->tools[t].cfg->radius);
  }
  verr_t e;
  uint32_t v0 = m->topology_version;
  if (!in) {
    if (so->tool < 0) return;
    uint64_t t0 = vtime_mono_ns();
    int rc = tet_model_cut_end(so->tet, &e);
    account(s, o, v0, t0, rc, &e);
    cut_finished(rt, so, organ);
    return;
  }
  if (so->tool < 0) {
    so->tool = t;
    const tet_cut_t *c = tet_model_cut_mesh(so->tet);
    so->edges0 = c ? c->stats.cut_edges : 0;
  }
  uint64_t t0 = vtime_mono_ns();
  int rc = tet_model_cut_advance(so->tet, tip, handle, &e);
  account(s, o, v0, t0, rc, &e);
  const tet_cut_t *c = tet_model_cut_mesh(so->tet);
  cut_begin_if_touched(rt, so, organ, c && c->stats.cut_edges > so->edges0);
}

static void step_ms(runtime_t *rt, struct scalpel *s, size_t organ) {
  scalpel_organ_t *so = &s->organ[organ];
  organ_rt_t *o = &rt->organs[organ];
  model_t *m = o->model;
  int t = cutter_for(rt, m, so->tool);
  verr_t e;
  uint32_t v0 = m->topology_version;
  uint64_t t0 = vtime_mono_ns();
  int rc;
  if (t < 0 && so->tool >= 0) { /* button or tool released: the cut ends now */
    rc = ms_cut_end(so->ms, &e);
    account(s, o, v0, t0, rc, &e);
    cut_finished(rt, so, organ);
    return;
  }
  if (t < 0) {
    /* Nobody cuts: the parked blade crosses nothing, and the cutter goes on
     * refining its stability estimate after the last cut. */
    rc = ms_cut_step(so->ms, s->parked, s->parked, PARKED_RADIUS, &e);
    account(s, o, v0, t0, rc, &e);
    return;
  }
  so->tool = t;
  const tool_rt_t *tool = &rt->tools[t];
  double tip[3], handle[3];
  blade(tool, tip, handle);
  int was_active = ms_cut_active(so->ms);
  rc = ms_cut_step(so->ms, handle, tip, tool->cfg->radius, &e);
  account(s, o, v0, t0, rc, &e);
  int active = ms_cut_active(so->ms);
  cut_begin_if_touched(rt, so, organ, active);
  /* The axis left the tissue: the cutter ended that cut by itself. A new
   * one starts (and is reported) when it crosses the surface again. */
  if (was_active && !active && so->touched) {
    push(rt, IEV_CUT_END, so->tool, organ, (double)(so->st.topology_changes - so->changes0));
    so->touched = 0;
  }
}

void scalpel_after_organ_step(runtime_t *rt, size_t organ) {
  struct scalpel *s = rt->scalpel;
  if (!s || organ >= rt->norgans) return;
  if (s->organ[organ].tet)
    step_tet(rt, s, organ);
  else if (s->organ[organ].ms)
    step_ms(rt, s, organ);
}

size_t scalpel_incision_width(const runtime_t *rt, size_t organ, double *mean, double *max) {
  if (mean) *mean = 0;
  if (max) *max = 0;
  if (!rt->scalpel || organ >= rt->norgans || !rt->scalpel->organ[organ].ms) return 0;
  return ms_cut_incision_width(rt->scalpel->organ[organ].ms, mean, max);
}

const scalpel_organ_stats_t *scalpel_stats(const runtime_t *rt, size_t organ) {
  if (!rt->scalpel || organ >= rt->norgans) return NULL;
  return &rt->scalpel->organ[organ].st;
}

int scalpel_has_cutter(const runtime_t *rt, size_t organ) {
  if (!rt->scalpel || organ >= rt->norgans) return 0;
  const scalpel_organ_t *so = &rt->scalpel->organ[organ];
  return tet_model_cut_mesh(so->tet) != NULL || so->ms != NULL;
}

int scalpel_owns_topology(const runtime_t *rt, size_t organ) {
  return rt->scalpel && organ < rt->norgans && rt->scalpel->organ[organ].tet != NULL;
}

int scalpel_save_topology(const runtime_t *rt, size_t organ, state_blob_t *b) {
  if (!scalpel_owns_topology(rt, organ)) return -1;
  return tet_model_cut_save(rt->scalpel->organ[organ].tet, b);
}

int scalpel_restore_topology(runtime_t *rt, size_t organ, state_blob_t *b, size_t nnodes, const double *x,
                             const double *v, verr_t *err) {
  if (!scalpel_owns_topology(rt, organ)) return verr_set(err, "no cutter holds this organ's topology");
  return tet_model_cut_restore(rt->scalpel->organ[organ].tet, b, nnodes, x, v, err);
}

uint64_t scalpel_take_error(runtime_t *rt, char *msg, size_t len) {
  struct scalpel *s = rt->scalpel;
  if (!s || s->refused == s->refused_taken) return 0;
  s->refused_taken = s->refused;
  snprintf(msg, len, "%s", s->last_error);
  return s->refused;
}

void scalpel_print_summary(const runtime_t *rt, FILE *f) {
  if (!rt->scalpel) return;
  for (size_t i = 0; i < rt->norgans; i++) {
    const scalpel_organ_stats_t *st = &rt->scalpel->organ[i].st;
    const model_t *m = rt->organs[i].model;
    if (!st->can_cut) continue;
    double mean = 0, max = 0;
    scalpel_incision_width(rt, i, &mean, &max);
    fprintf(f,
            "CUT organ=%s model=%s cuts=%" PRIu64 " topology_changes=%" PRIu64 " topology_version=%u refused=%" PRIu64
            " vertices=%zu->%zu triangles=%zu cut_call_us_mean=%.1f cut_call_us_max=%.1f change_call_us_mean=%.1f "
            "change_call_us_max=%.1f keyframe_bytes_max=%zu incision_width_mean_mm=%.3f incision_width_max_mm=%.3f\n",
            rt->organs[i].cfg->name, m->ops->name, st->cuts, st->topology_changes, m->topology_version, st->refused,
            st->nsurf_initial, m->nsurf, m->nsurf_tris, st->calls ? st->call_us_sum / (double)st->calls : 0,
            st->call_us_max, st->change_calls ? st->change_us_sum / (double)st->change_calls : 0, st->change_us_max,
            st->max_keyframe_bytes, mean * 1e3, max * 1e3);
  }
}
