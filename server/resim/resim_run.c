/* SPDX-License-Identifier: Apache-2.0 */
#include "resim/resim_run.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_delta.h"
#include "resim/resim_measures.h"
#include "runtime/checkpoint_state.h"
#include "training/measures_blob.h"

int resim_check_scene(const runtime_t *rt, const resim_recording_t *rec, verr_t *err) {
  const scene_t *sc = &rt->scene;
  if (strcmp(sc->name, rec->scene) != 0)
    return verr_set(err, "scene mismatch: %s is scene '%s', the recording is of scene '%s'", sc->path, sc->name,
                    rec->scene);
  if (fabs(sc->dt - rec->dt) > 1e-12 * sc->dt)
    return verr_set(err, "scene mismatch: %s has dt %g s, the recording %g s", sc->path, sc->dt, rec->dt);
  if ((float)sc->quant_step != rec->quant_step)
    return verr_set(err, "scene mismatch: %s has quant_step %g m, the recording %g m", sc->path, sc->quant_step,
                    (double)rec->quant_step);
  if (rt->norgans != rec->norgans)
    return verr_set(err, "scene mismatch: %s has %zu organ(s), the recording %zu", sc->path, rt->norgans, rec->norgans);
  for (size_t i = 0; i < rt->norgans; i++) {
    const model_t *m = rt->organs[i].model;
    const resim_organ_info_t *o = &rec->organs[i];
    if (strcmp(rt->organs[i].cfg->name, o->name) != 0)
      return verr_set(err, "scene mismatch: organ %zu is '%s' in %s, '%s' in the recording", i, rt->organs[i].cfg->name,
                      sc->path, o->name);
    if (m->nsurf != o->nverts || m->nsurf_tris != o->ntris)
      return verr_set(err,
                      "scene mismatch: organ '%s' has %zu vertices / %zu triangles in %s, %u / %u in the recording",
                      o->name, m->nsurf, m->nsurf_tris, sc->path, o->nverts, o->ntris);
  }
  if (rt->ntools != rec->ntools)
    return verr_set(err, "scene mismatch: %s has %zu tool(s), the recording %zu", sc->path, rt->ntools, rec->ntools);
  return 0;
}

typedef struct organ_buf {
  float *mesh;   /* 3 n: the recorded mesh of a frame */
  uint32_t *idx; /* n: re-encoding for the exactness check */
  int16_t *dq;   /* 3 n */
  size_t cap;    /* vertices the buffers hold */
} organ_buf_t;

/* Grows an organ's buffers to n vertices (a topology change can add some). */
static int buf_fit(organ_buf_t *b, size_t n) {
  if (n <= b->cap && b->mesh) return 0;
  float *m = realloc(b->mesh, (3 * n + 1) * sizeof(float));
  if (m) b->mesh = m;
  uint32_t *i = realloc(b->idx, (n + 1) * sizeof(uint32_t));
  if (i) b->idx = i;
  int16_t *d = realloc(b->dq, (3 * n + 1) * sizeof(int16_t));
  if (d) b->dq = d;
  if (!m || !i || !d) return -1;
  b->cap = n;
  return 0;
}

/* What a run carries from step to step. */
typedef struct run_ctx {
  runtime_t *rt;
  resim_recording_t *rec;
  const resim_hooks_t *hooks;
  resim_result_t *res;
  organ_buf_t bufs[SCENE_MAX_ORGANS];
  /* The server's MeshState topology_version per organ (mesh_publisher.h:
   * +1 per retopo, a cut or a rebuild) and the model version it follows. */
  uint32_t pubver[SCENE_MAX_ORGANS], modelver[SCENE_MAX_ORGANS];
  uint32_t epoch; /* rebuilds so far */
  int paused;
  resim_measures_t measures; /* the ToolMetrics the server computes */
  size_t nev, capev;
  resim_event_t *ev; /* the interaction events the re-simulation reported */
  verr_t *err;
} run_ctx_t;

static void add_frame(resim_organ_result_t *r, uint64_t step, double max_err, double sum_sq, size_t n, int exact) {
  r->frames++;
  if (exact) r->exact++;
  if (r->frames == 1 || max_err > r->max_err) {
    r->max_err = max_err;
    r->worst_step = step;
  }
  r->sum_sq += sum_sq;
  r->nsq += n;
}

/* Per-coordinate max and summed squared per-vertex distance between the
 * re-simulated x and a recorded float mesh. */
static double compare(const double *x, const float *rec, size_t n, double *sum_sq) {
  double mx = 0, s = 0;
  for (size_t v = 0; v < n; v++) {
    double d2 = 0;
    for (int k = 0; k < 3; k++) {
      double d = x[3 * v + k] - (double)rec[3 * v + k];
      mx = fmax(mx, fabs(d));
      d2 += d * d;
    }
    s += d2;
  }
  *sum_sq = s;
  return mx;
}

static const resim_keyframe_t *find_key(const resim_recording_t *rec, uint32_t organ, uint32_t seq, uint32_t topo) {
  /* Few keyframes per session: a scan is enough. */
  for (size_t i = rec->nkeys; i-- > 0;)
    if (rec->keys[i].organ == organ && rec->keys[i].keyframe_seq == seq && rec->keys[i].topology_version == topo)
      return &rec->keys[i];
  return NULL;
}

/* A frame that cannot be compared with the re-simulated surface (another
 * vertex count: the topology differs, or no keyframe to apply to). */
static void unmatched(resim_result_t *res, uint32_t organ, uint64_t step, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static void unmatched(resim_result_t *res, uint32_t organ, uint64_t step, const char *fmt, ...) {
  if (res->organs[organ].unmatched++ == 0 && !res->first_unmatched[0]) {
    int k = snprintf(res->first_unmatched, sizeof res->first_unmatched, "organ %u step %llu: ", organ,
                     (unsigned long long)step);
    va_list ap;
    va_start(ap, fmt);
    if (k > 0 && (size_t)k < sizeof res->first_unmatched)
      vsnprintf(res->first_unmatched + k, sizeof res->first_unmatched - (size_t)k, fmt, ap);
    va_end(ap);
  }
}

static void compare_key(run_ctx_t *c, resim_keyframe_t *key) {
  const model_t *m = c->rt->organs[key->organ].model;
  key->done = 1;
  uint32_t nv = key->nverts ? key->nverts : c->rec->organs[key->organ].nverts;
  if (nv != m->nsurf || (key->tris && key->ntris != m->nsurf_tris)) {
    unmatched(c->res, key->organ, key->step,
              "keyframe of topology %u has %u vertices / %u triangles, the re-simulation %zu / %zu",
              key->topology_version, nv, key->ntris, m->nsurf, m->nsurf_tris);
    return;
  }
  double ss;
  double mx = compare(m->surf_x, key->pos, m->nsurf, &ss);
  int exact = 1;
  for (size_t i = 0; i < 3 * m->nsurf && exact; i++) exact = (float)m->surf_x[i] == key->pos[i];
  if (key->tris && exact)
    exact = !key->ntris || !memcmp(key->tris, m->surf_tris, 3 * (size_t)key->ntris * sizeof(uint32_t));
  resim_organ_result_t *r = &c->res->organs[key->organ];
  r->keyframes++;
  add_frame(r, key->step, mx, ss, m->nsurf, exact);
  if (c->hooks && c->hooks->frame)
    c->hooks->frame(c->hooks->arg, key->step, key->organ, 1, mx, m->nsurf ? sqrt(ss / (double)m->nsurf) : 0, exact);
}

static void compare_delta(run_ctx_t *c, resim_delta_t *d) {
  const model_t *m = c->rt->organs[d->organ].model;
  organ_buf_t *b = &c->bufs[d->organ];
  resim_organ_result_t *r = &c->res->organs[d->organ];
  d->done = 1;
  const resim_keyframe_t *key = find_key(c->rec, d->organ, d->keyframe_seq, d->topology_version);
  verr_t e;
  if (!key) {
    unmatched(c->res, d->organ, d->step, "frame %u: keyframe %u was not recorded", d->frame_seq, d->keyframe_seq);
    return;
  }
  uint32_t nv = key->nverts ? key->nverts : c->rec->organs[d->organ].nverts;
  if (nv != m->nsurf) {
    unmatched(c->res, d->organ, d->step, "frame %u of topology %u: %u vertices, the re-simulation %zu", d->frame_seq,
              d->topology_version, nv, m->nsurf);
    return;
  }
  if (buf_fit(b, m->nsurf)) {
    unmatched(c->res, d->organ, d->step, "out of memory");
    return;
  }
  if (mesh_delta_apply(key->pos, m->nsurf, d->quant, d->idx, d->count, d->dq, d->dq_len, b->mesh, &e)) {
    unmatched(c->res, d->organ, d->step, "frame %u: %s", d->frame_seq, e.msg);
    return;
  }
  double ss;
  double mx = compare(m->surf_x, b->mesh, m->nsurf, &ss);
  long n = mesh_delta_encode(key->pos, m->surf_x, m->nsurf, d->quant, b->idx, b->dq);
  int exact = n == (long)d->count && 3 * (size_t)n == d->dq_len &&
              (n == 0 || (memcmp(b->idx, d->idx, (size_t)n * sizeof *b->idx) == 0 &&
                          memcmp(b->dq, d->dq, 3 * (size_t)n * sizeof *b->dq) == 0));
  add_frame(r, d->step, mx, ss, m->nsurf, exact);
  if (c->hooks && c->hooks->frame)
    c->hooks->frame(c->hooks->arg, d->step, d->organ, 0, mx, m->nsurf ? sqrt(ss / (double)m->nsurf) : 0, exact);
}

/* Frames sorted by organ, topology version, step (then seq): the frames
 * of one organ at one step of one topology are a run found by bisection. */
static int cmp_u64(uint64_t a, uint64_t b) { return a < b ? -1 : a > b; }
/* Organ, then topology version, then step, then the sequence number. */
static int cmp_otp(uint64_t oa, uint64_t ta, uint64_t sa, uint64_t qa, uint64_t ob, uint64_t tb, uint64_t sb,
                   uint64_t qb) {
  int r = cmp_u64(oa, ob);
  if (!r) r = cmp_u64(ta, tb);
  if (!r) r = cmp_u64(sa, sb);
  return r ? r : cmp_u64(qa, qb);
}
static int cmp_key_otp(const void *a, const void *b) {
  const resim_keyframe_t *x = a, *y = b;
  return cmp_otp(x->organ, x->topology_version, x->step, x->keyframe_seq, y->organ, y->topology_version, y->step,
                 y->keyframe_seq);
}
static int cmp_delta_otp(const void *a, const void *b) {
  const resim_delta_t *x = a, *y = b;
  return cmp_otp(x->organ, x->topology_version, x->step, x->frame_seq, y->organ, y->topology_version, y->step,
                 y->frame_seq);
}
static int cmp_metrics(const void *a, const void *b) {
  const resim_tool_metrics_t *x = a, *y = b;
  if (x->epoch != y->epoch) return x->epoch < y->epoch ? -1 : 1;
  if (x->step != y->step) return x->step < y->step ? -1 : 1;
  return x->tool < y->tool ? -1 : x->tool > y->tool;
}

/* A recorded ToolMetrics against the re-simulated measures: every field bit
 * for bit. */
static void compare_metrics(run_ctx_t *c, resim_tool_metrics_t *m) {
  m->done = 1;
  resim_metrics_result_t *r = &c->res->metrics;
  r->compared++;
  if (m->tool >= c->rt->ntools) {
    r->differ++;
    return;
  }
  resim_tool_metrics_t x;
  resim_measures_fill(&c->measures, c->rt, m->tool, &x);
  const char *field = NULL;
  double a = 0, b = 0;
#define FIELD(f)                                                                                                       \
  if (!field && x.f != m->f) field = #f, a = (double)m->f, b = (double)x.f;
  FIELD(peak_force)
  FIELD(time_above[0])
  FIELD(time_above[1])
  FIELD(time_above[2])
  FIELD(contact_time)
  FIELD(path_length)
  FIELD(grasps)
  FIELD(grasp_time)
  FIELD(tasks_completed)
  FIELD(operation_time)
#undef FIELD
  if (!field) return;
  if (r->differ++ == 0)
    snprintf(r->first_difference, sizeof r->first_difference,
             "tool %u at step %llu: %s recorded %.9g, re-simulated %.9g", m->tool, (unsigned long long)m->step, field,
             a, b);
}

static int cmp_object(const void *a, const void *b) {
  const resim_object_t *x = a, *y = b;
  if (x->epoch != y->epoch) return x->epoch < y->epoch ? -1 : 1;
  if (x->step != y->step) return x->step < y->step ? -1 : 1;
  return x->object < y->object ? -1 : x->object > y->object;
}

#define LOWER_BOUND(arr, n, lt)                                                                                        \
  size_t lo = 0, hi = (n);                                                                                             \
  while (lo < hi) {                                                                                                    \
    size_t mid = lo + (hi - lo) / 2;                                                                                   \
    if (lt(&(arr)[mid]))                                                                                               \
      lo = mid + 1;                                                                                                    \
    else                                                                                                               \
      hi = mid;                                                                                                        \
  }

/* Compares every recorded frame of the runtime's current state: the
 * organs' surfaces at this step of their current topology, and the
 * objects at this step of this epoch. */
static void compare_now(run_ctx_t *c) {
  uint64_t k = c->rt->steps;
  resim_recording_t *rec = c->rec;
  for (uint32_t i = 0; i < c->rt->norgans; i++) {
    uint32_t v = c->pubver[i];
#define KEY_LT(p)                                                                                                      \
  ((p)->organ < i || ((p)->organ == i && ((p)->topology_version < v || ((p)->topology_version == v && (p)->step < k))))
    {
      LOWER_BOUND(rec->keys, rec->nkeys, KEY_LT)
      for (size_t j = lo;
           j < rec->nkeys && rec->keys[j].organ == i && rec->keys[j].topology_version == v && rec->keys[j].step == k;
           j++)
        if (!rec->keys[j].done) compare_key(c, &rec->keys[j]);
    }
    {
      LOWER_BOUND(rec->deltas, rec->ndeltas, KEY_LT)
      for (size_t j = lo; j < rec->ndeltas && rec->deltas[j].organ == i && rec->deltas[j].topology_version == v &&
                          rec->deltas[j].step == k;
           j++)
        if (!rec->deltas[j].done) compare_delta(c, &rec->deltas[j]);
    }
#undef KEY_LT
  }
  uint32_t e = c->epoch;
#define OBJ_LT(p) ((p)->epoch < e || ((p)->epoch == e && (p)->step < k))
  {
    LOWER_BOUND(rec->metrics, rec->nmetrics, OBJ_LT)
    for (size_t j = lo; j < rec->nmetrics && rec->metrics[j].epoch == e && rec->metrics[j].step == k; j++)
      if (!rec->metrics[j].done) compare_metrics(c, &rec->metrics[j]);
  }
  LOWER_BOUND(rec->objects, rec->nobjects, OBJ_LT)
#undef OBJ_LT
  for (size_t j = lo; j < rec->nobjects && rec->objects[j].epoch == e && rec->objects[j].step == k; j++) {
    resim_object_t *o = &rec->objects[j];
    if (o->done) continue;
    o->done = 1;
    resim_object_result_t *r = &c->res->objects;
    if (o->object >= c->rt->nstones) {
      r->mismatched++;
      continue;
    }
    const stone_t *st = &c->rt->stones[o->object];
    double mx = 0;
    int exact = 1;
    for (int q = 0; q < 3; q++) {
      mx = fmax(mx, fabs(st->pos[q] - (double)o->pos[q]));
      exact = exact && (float)st->pos[q] == o->pos[q];
    }
    int same = st->held_by == o->held_by && (st->removed != 0) == (o->removed != 0);
    r->compared++;
    if (exact && same) r->exact++;
    if (!same && r->mismatched++ == 0) r->first_mismatch_step = k;
    if (mx > r->max_err) {
      r->max_err = mx;
      r->worst_step = k;
    }
  }
}

/* After a step or a rebuild: an organ whose model changed topology has a
 * new MeshState topology version (as the server's follow_topology). */
static void follow(run_ctx_t *c) {
  for (size_t i = 0; i < c->rt->norgans; i++)
    if (c->rt->organs[i].topology_version != c->modelver[i]) {
      c->modelver[i] = c->rt->organs[i].topology_version;
      c->pubver[i]++;
    }
}

static int push_event(run_ctx_t *c, int kind, int tool, int organ, double value) {
  if (c->nev == c->capev) {
    size_t n = c->capev ? 2 * c->capev : 64;
    resim_event_t *p = realloc(c->ev, n * sizeof *p);
    if (!p) return -1;
    c->ev = p;
    c->capev = n;
  }
  c->ev[c->nev++] = (resim_event_t){.kind = kind, .tool = tool, .organ = organ, .value = value, .step = c->rt->steps};
  return 0;
}

/* One server step: the runtime steps, its interaction events are taken (as
 * the server publishes them), topologies followed, frames compared. */
static void step(run_ctx_t *c) {
  c->res->rollbacks += (uint64_t)runtime_step(c->rt);
  c->res->steps++;
  follow(c);
  for (size_t i = 0; i < c->rt->events.n; i++) {
    const iev_t *e = &c->rt->events.ev[i];
    push_event(c, (int)e->kind, e->tool, e->organ, e->value);
  }
  c->rt->events.n = 0;
  resim_measures_step(&c->measures, c->rt);
  compare_now(c);
}

/* A rebuild (RESET, SET_MATERIAL) from `sc`, or from `old` when the models
 * refuse `sc`, as the server's rebuild_runtime. */
static int rebuild(run_ctx_t *c, const scene_t *sc, const scene_t *old) {
  verr_t e;
  runtime_destroy(c->rt);
  if (runtime_init(c->rt, sc, &e)) {
    runtime_destroy(c->rt);
    if (runtime_init(c->rt, old, &e)) return verr_set(c->err, "cannot rebuild the scene after a control: %s", e.msg);
  }
  c->epoch++;
  c->res->rebuilds++;
  resim_measures_init(&c->measures, c->rt);
  for (size_t i = 0; i < c->rt->norgans; i++) {
    c->modelver[i] = c->rt->organs[i].topology_version;
    c->pubver[i]++;
  }
  compare_now(c);
  return 0;
}

/* SET_MATERIAL values as session_control.c applies them: negative keeps. */
static void edit_material(scene_material_t *m, const double v[4]) {
  if (v[0] >= 0) m->stiffness = v[0];
  if (v[1] >= 0) m->damping = v[1];
  if (v[2] >= 0) m->home_stiffness = v[2];
  if (v[3] > 0) m->mass = v[3];
}

static int apply_control(run_ctx_t *c, const resim_input_t *in) {
  c->res->controls++;
  if (in->result < 0) return 0; /* refused: nothing changed */
  switch (in->control) {
  case RESIM_CTL_PAUSE:
    c->paused = 1;
    return 0;
  case RESIM_CTL_RESUME:
    c->paused = 0;
    return 0;
  case RESIM_CTL_START_TASK:
    if (in->task >= 0 && (size_t)in->task < c->rt->ntasks) {
      tasks_start(&c->rt->tasks[in->task], c->rt->sim_time);
      return push_event(c, IEV_TASK_STARTED, c->rt->scene.tasks[in->task].tool, -1, 1);
    }
    return verr_set(c->err, "START_TASK names task %d, the scene has %zu", in->task, c->rt->ntasks);
  case RESIM_CTL_RESET:
  case RESIM_CTL_SET_MATERIAL: {
    if (in->result != 1 && in->result != 2) return 0;
    scene_t *edit = malloc(sizeof *edit), *old = malloc(sizeof *old);
    int rc = -1;
    if (edit && old) {
      *edit = c->rt->scene;
      *old = c->rt->scene;
      if (in->control == RESIM_CTL_SET_MATERIAL && in->result == 1 && in->ctl_organ >= 0 &&
          (size_t)in->ctl_organ < edit->norgans)
        edit_material(&edit->organs[in->ctl_organ].material, in->values);
      rc = rebuild(c, in->result == 1 ? edit : old, old);
    } else {
      verr_set(c->err, "out of memory for a rebuild");
    }
    free(edit);
    free(old);
    return rc;
  }
  case RESIM_CTL_SET_THRESHOLDS:
    if (in->ctl_tool >= 0) resim_measures_levels(&c->measures, (size_t)in->ctl_tool, in->values);
    return 0;
  default: /* roles: the effective commands they lead to are recorded */
    return 0;
  }
}

/* Steps until the runtime is at `step` of `epoch`; -1 (err) when the
 * recording asks for a state the re-simulation cannot reach. */
static int advance(run_ctx_t *c, uint32_t epoch, uint64_t to) {
  if (epoch != c->epoch || to < c->rt->steps || (to > c->rt->steps && c->paused))
    return verr_set(c->err,
                    "the recorded inputs continue at step %llu of epoch %u, the re-simulation is at step %llu of "
                    "epoch %u%s: the recording does not follow from its own inputs",
                    (unsigned long long)to, epoch, (unsigned long long)c->rt->steps, c->epoch,
                    c->paused ? " (paused)" : "");
  while (c->rt->steps < to) {
    step(c);
    if (c->hooks && c->hooks->progress && c->rt->steps % 1000 == 0)
      c->hooks->progress(c->hooks->arg, c->rt->steps, c->rec->last_step);
  }
  return 0;
}

/* The last step with a recorded frame or object of the current topology
 * versions and epoch: where a run with no inputs left stops. */
static uint64_t end_step(const run_ctx_t *c) {
  uint64_t end = c->rt->steps;
  const resim_recording_t *rec = c->rec;
  for (size_t j = 0; j < rec->nkeys; j++)
    if (rec->keys[j].organ < c->rt->norgans && rec->keys[j].topology_version == c->pubver[rec->keys[j].organ] &&
        rec->keys[j].step > end)
      end = rec->keys[j].step;
  for (size_t j = 0; j < rec->ndeltas; j++)
    if (rec->deltas[j].organ < c->rt->norgans && rec->deltas[j].topology_version == c->pubver[rec->deltas[j].organ] &&
        rec->deltas[j].step > end)
      end = rec->deltas[j].step;
  for (size_t j = 0; j < rec->nobjects; j++)
    if (rec->objects[j].epoch == c->epoch && rec->objects[j].step > end) end = rec->objects[j].step;
  for (size_t j = 0; j < rec->nmetrics; j++)
    if (rec->metrics[j].epoch == c->epoch && rec->metrics[j].step > end) end = rec->metrics[j].step;
  return end;
}

/* The applied inputs of the recording (issue 16), in the server's order. */
static int run_applied(run_ctx_t *c) {
  resim_recording_t *rec = c->rec;
  for (size_t i = 0; i < rec->ninputs; i++) {
    const resim_input_t *in = &rec->inputs[i];
    if (advance(c, in->epoch, in->step)) return -1;
    switch (in->kind) {
    case RESIM_IN_COMMAND:
      runtime_command_tool(c->rt, in->tool, &in->cmd);
      c->res->commands++;
      break;
    case RESIM_IN_RELEASE:
      runtime_release_tool(c->rt, in->tool);
      c->res->releases++;
      break;
    case RESIM_IN_CONTROL:
      if (apply_control(c, in)) return -1;
      break;
    }
  }
  if (c->paused) return 0; /* the session ended paused: nothing moves any more */
  return advance(c, c->epoch, end_step(c));
}

/* A recording made before AppliedInput existed: the tool positions and
 * device forces, scheduled from ToolCommand and ContactFeedback
 * (resim_schedule.h); buttons, orientation and controls are not known. */
static int run_scheduled(run_ctx_t *c) {
  runtime_t *rt = c->rt;
  resim_recording_t *rec = c->rec;
  uint64_t nsteps = rec->last_step;
  int32_t *sched[SCENE_MAX_TOOLS] = {0};
  int rc = 0;
  for (size_t t = 0; t < rt->ntools && !rc; t++) {
    sched[t] = malloc((nsteps + 1) * sizeof(int32_t));
    if (!sched[t]) {
      rc = verr_set(c->err, "out of memory for a %llu-step schedule", (unsigned long long)nsteps);
      break;
    }
    verr_t e;
    if (resim_schedule_build(&rec->tools[t], nsteps, sched[t], &c->res->sched[t], &e))
      rc = verr_set(c->err, "tool %zu ('%s'): %s", t, rt->tools[t].cfg->name, e.msg);
  }
  if (!rc) {
    int32_t applied[SCENE_MAX_TOOLS];
    for (size_t t = 0; t < SCENE_MAX_TOOLS; t++) applied[t] = -1;
    uint64_t every = nsteps / 100 ? nsteps / 100 : 1;
    for (uint64_t k = 1; k <= nsteps; k++) {
      /* What read_commands did before this step. */
      for (size_t t = 0; t < rt->ntools; t++) {
        int32_t s = sched[t][k];
        if (s == applied[t]) continue;
        if (s < 0) {
          runtime_release_tool(rt, t);
        } else {
          const resim_cmd_t *cmd = &rec->tools[t].cmd[s];
          runtime_set_tool(rt, t, cmd->pos, cmd->max_force);
        }
        applied[t] = s;
      }
      step(c);
      if (c->hooks && c->hooks->progress && k % every == 0) c->hooks->progress(c->hooks->arg, k, nsteps);
    }
  }
  for (size_t t = 0; t < SCENE_MAX_TOOLS; t++) free(sched[t]);
  return rc;
}

/* A resumed session (SceneSource.resume_state): where each tool's measures
 * are in the state, checked as they are read. */
static const char *resume_tool(void *ctx, state_blob_t *b, size_t t) {
  resim_source_t *s = ctx;
  s->tool_at[t] = b->at;
  thr_tracker_t scratch = {0};
  uint32_t grasps;
  double grasp_time;
  return measures_blob_get(b, &scratch, &grasps, &grasp_time);
}

int resim_resume(runtime_t *rt, resim_recording_t *rec, verr_t *err) {
  resim_source_t *s = &rec->source;
  if (!s->resume_len) return 0;
  state_blob_t b = {.p = s->resume, .len = s->resume_len, .cap = s->resume_len};
  ckpt_session_io_t io = {.ctx = s, .get_tool = resume_tool};
  char what[200] = "";
  verr_t e = {{0}};
  int rc = ckpt_state_get(&b, rt, &io, what, sizeof what, &e);
  if (rc != 1)
    return verr_set(err,
                    "the session resumed from a checkpoint (sha256 %s) whose recorded state cannot be restored: %s",
                    s->resume_sha256[0] ? s->resume_sha256 : "unknown", rc == -1 ? what : e.msg);
  s->resumed = 1;
  s->resumed_step = rt->steps;
  return 0;
}

/* The run starts where the server resumed: each tool's measures as it
 * restored them (levels stay the scene's; no grasp is held), and the
 * restored topologies followed from a scene built from rest (as the
 * server's follow_topology after checkpoint_load). */
static void start_resumed(run_ctx_t *c) {
  resim_source_t *s = &c->rec->source;
  for (size_t t = 0; t < c->rt->ntools; t++) {
    state_blob_t b = {.p = s->resume, .len = s->resume_len, .cap = s->resume_len, .at = s->tool_at[t]};
    measures_blob_get(&b, &c->measures.thr[t], &c->measures.grasps[t], &c->measures.grasp_time[t]);
    c->measures.was_holding[t] = 0;
  }
  for (size_t i = 0; i < c->rt->norgans; i++) c->modelver[i] = 0;
  follow(c);
  c->res->resumed_step = s->resumed_step;
}

/* The recorded interaction events against the re-simulation's, in order. */
static void compare_events(run_ctx_t *c) {
  resim_event_result_t *r = &c->res->events;
  const resim_recording_t *rec = c->rec;
  r->recorded = rec->nevents;
  r->resim = c->nev;
  size_t n = rec->nevents < c->nev ? rec->nevents : c->nev;
  for (size_t i = 0; i < n; i++) {
    const resim_event_t *a = &rec->events[i], *b = &c->ev[i];
    if (a->kind == b->kind && a->tool == b->tool && a->organ == b->organ && a->step == b->step &&
        a->value == b->value) {
      r->equal++;
      continue;
    }
    if (!r->first_difference[0])
      snprintf(r->first_difference, sizeof r->first_difference,
               "event %zu: recorded kind %d tool %d organ %d value %.9g at step %llu, re-simulated kind %d tool %d "
               "organ %d value %.9g at step %llu",
               i, a->kind, a->tool, a->organ, a->value, (unsigned long long)a->step, b->kind, b->tool, b->organ,
               b->value, (unsigned long long)b->step);
  }
  if (!r->first_difference[0] && rec->nevents != c->nev)
    snprintf(r->first_difference, sizeof r->first_difference, "%zu event(s) recorded, %zu re-simulated", rec->nevents,
             c->nev);
}

int resim_run(runtime_t *rt, resim_recording_t *rec, const resim_hooks_t *hooks, resim_result_t *res, verr_t *err) {
  memset(res, 0, sizeof *res);
  static run_ctx_t zero;
  run_ctx_t *c = malloc(sizeof *c);
  if (!c) return verr_set(err, "out of memory");
  *c = zero;
  c->rt = rt;
  c->rec = rec;
  c->hooks = hooks;
  c->res = res;
  c->err = err;
  for (size_t i = 0; i < rt->norgans; i++) c->modelver[i] = rt->organs[i].topology_version;
  if (rec->nkeys) qsort(rec->keys, rec->nkeys, sizeof *rec->keys, cmp_key_otp);
  if (rec->ndeltas) qsort(rec->deltas, rec->ndeltas, sizeof *rec->deltas, cmp_delta_otp);
  if (rec->nobjects) qsort(rec->objects, rec->nobjects, sizeof *rec->objects, cmp_object);
  if (rec->nmetrics) qsort(rec->metrics, rec->nmetrics, sizeof *rec->metrics, cmp_metrics);
  for (size_t i = 0; i < rec->nmetrics; i++) rec->metrics[i].done = 0;
  resim_measures_init(&c->measures, rt);
  if (rec->source.resumed) start_resumed(c);
  for (size_t i = 0; i < rec->nkeys; i++) rec->keys[i].done = 0;
  for (size_t i = 0; i < rec->ndeltas; i++) rec->deltas[i].done = 0;
  for (size_t i = 0; i < rec->nobjects; i++) rec->objects[i].done = 0;
  res->applied = rec->ninputs > 0;
  compare_now(c); /* the keyframes of step 0 */
  int rc = res->applied ? run_applied(c) : run_scheduled(c);
  if (rc && !res->applied) { /* an unusable schedule: an error, as before */
    for (size_t i = 0; i < SCENE_MAX_ORGANS; i++) {
      free(c->bufs[i].mesh);
      free(c->bufs[i].idx);
      free(c->bufs[i].dq);
    }
    free(c->ev);
    free(c);
    return -1;
  }
  if (rc) {
    res->diverged = 1;
    snprintf(res->divergence, sizeof res->divergence, "%s", err->msg);
  }
  /* Frames the run never reached: another topology, epoch or end. */
  for (size_t i = 0; i < rec->nkeys; i++)
    if (!rec->keys[i].done && rec->keys[i].organ < rt->norgans) res->organs[rec->keys[i].organ].unreached++;
  for (size_t i = 0; i < rec->ndeltas; i++)
    if (!rec->deltas[i].done && rec->deltas[i].organ < rt->norgans) res->organs[rec->deltas[i].organ].unreached++;
  for (size_t i = 0; i < rec->nobjects; i++)
    if (!rec->objects[i].done) res->objects.unreached++;
  for (size_t i = 0; i < rec->nmetrics; i++)
    if (!rec->metrics[i].done) res->metrics.unreached++;
  compare_events(c);
  res->epochs = c->epoch;
  for (size_t i = 0; i < SCENE_MAX_ORGANS; i++) {
    free(c->bufs[i].mesh);
    free(c->bufs[i].idx);
    free(c->bufs[i].dq);
  }
  free(c->ev);
  free(c);
  return 0;
}
