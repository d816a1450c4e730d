/* SPDX-License-Identifier: Apache-2.0 */
#include "runtime/checkpoint_state.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "runtime/step_cut.h"

/* Layout (native byte order; the session puts its magic before and its
 * CRC after):
 *   scene_name[64] sim_time steps
 *   norgans, per organ: nnodes topology_version x[3 nnodes] v[3 nnodes]
 *                       (topology_version > 0: nbytes, the model's topology bytes)
 *   ntools, per tool: the session's tool record
 *   ntasks, per task: started completed t_start t_end
 *   nstones, per stone: pos[3] held_by removed
 *   the session's tail records */
int ckpt_state_put(state_blob_t *b, const runtime_t *rt, const ckpt_session_io_t *io, verr_t *err) {
  char name[SCENE_NAME_LEN] = {0};
  snprintf(name, sizeof name, "%s", rt->scene.name);
  sb_put(b, name, sizeof name);
  sb_put_f64(b, rt->sim_time);
  sb_put_u64(b, rt->steps);
  sb_put_u64(b, rt->norgans);
  for (size_t i = 0; i < rt->norgans; i++) {
    const model_t *m = rt->organs[i].model;
    sb_put_u64(b, m->nnodes);
    sb_put_u64(b, m->topology_version);
    sb_put(b, m->x, 3 * m->nnodes * sizeof(double));
    sb_put(b, m->v, 3 * m->nnodes * sizeof(double));
    if (m->topology_version == 0) continue;
    int by_cutter = scalpel_owns_topology(rt, i);
    if (!by_cutter && !m->ops->save_topology)
      return verr_set(err,
                      "organ '%s': its %s model cannot save a changed topology (topology %u): checkpoints stop here",
                      rt->organs[i].cfg->name, m->ops->name, m->topology_version);
    size_t at = b->len;
    sb_put_u64(b, 0); /* length, filled below */
    if (by_cutter ? scalpel_save_topology(rt, i, b) : m->ops->save_topology(m, b))
      return verr_set(err, "organ '%s': cannot save its topology%s", rt->organs[i].cfg->name,
                      b->bad ? " (out of memory)" : "");
    if (!b->bad) {
      uint64_t nbytes = b->len - at - 8;
      memcpy(b->p + at, &nbytes, 8);
    }
  }
  sb_put_u64(b, rt->ntools);
  for (size_t t = 0; t < rt->ntools; t++)
    if (io && io->put_tool) io->put_tool(io->ctx, b, t);
  sb_put_u64(b, rt->ntasks);
  for (size_t k = 0; k < rt->ntasks; k++) {
    const task_rt_t *t = &rt->tasks[k];
    sb_put_u64(b, (uint64_t)t->started);
    sb_put_u64(b, (uint64_t)t->completed);
    sb_put_f64(b, t->t_start);
    sb_put_f64(b, t->t_end);
  }
  sb_put_u64(b, rt->nstones);
  for (size_t k = 0; k < rt->nstones; k++) {
    const stone_t *st = &rt->stones[k];
    sb_put(b, st->pos, sizeof st->pos);
    sb_put_u64(b, (uint64_t)(int64_t)st->held_by);
    sb_put_u64(b, (uint64_t)st->removed);
  }
  if (io && io->put_tail) io->put_tail(io->ctx, b);
  return b->bad ? verr_set(err, "checkpoint: out of memory") : 0;
}

/* Where one organ's saved state sits in the bytes (the first pass). */
typedef struct organ_at {
  size_t nnodes, x, v; /* offsets of x and v */
  uint64_t topo;       /* saved topology_version */
  size_t blob, nblob;  /* the model's topology bytes */
} organ_at_t;

/* After a topology restore failed, other organs may already be restored:
 * the runtime is built again from its scene, so a refused state still
 * means "starting from rest". */
static int rebuild_at_rest(runtime_t *rt, verr_t *err) {
  scene_t *sc = malloc(sizeof *sc);
  if (!sc) return verr_set(err, "out of memory");
  *sc = rt->scene;
  runtime_destroy(rt);
  int rc = runtime_init(rt, sc, err);
  free(sc);
  return rc;
}

/* Restores the changed topologies (organs with topo > 0); 0, or -1 with
 * err (rt rebuilt at rest: a hook that fails after its checks may have
 * changed its model), or -2 when the rebuild failed too. */
static int restore_topologies(runtime_t *rt, const state_blob_t *b, const organ_at_t *at, verr_t *err) {
  for (size_t i = 0; i < rt->norgans; i++) {
    if (at[i].topo == 0) continue;
    model_t *m = rt->organs[i].model;
    size_t bytes = 3 * at[i].nnodes * sizeof(double);
    double *x = malloc(bytes ? bytes : 1), *v = malloc(bytes ? bytes : 1);
    state_blob_t tb = {.p = b->p + at[i].blob, .len = at[i].nblob};
    verr_t sub;
    int rc = -1;
    if (!x || !v) {
      verr_set(&sub, "out of memory");
    } else {
      memcpy(x, b->p + at[i].x, bytes); /* aligned copies: the file's offsets need not be */
      memcpy(v, b->p + at[i].v, bytes);
      rc = scalpel_owns_topology(rt, i) ? scalpel_restore_topology(rt, i, &tb, at[i].nnodes, x, v, &sub)
                                        : m->ops->restore_topology(m, &tb, at[i].nnodes, x, v, &sub);
      if (rc == 0 && (tb.at != tb.len || m->nnodes != at[i].nnodes)) {
        verr_set(&sub, "topology data of unexpected length");
        rc = -1;
      }
    }
    free(x);
    free(v);
    if (rc) {
      verr_set(err, "organ '%s': cannot restore its topology: %s", rt->organs[i].cfg->name, sub.msg);
      verr_t e2;
      return rebuild_at_rest(rt, &e2) ? -2 : -1;
    }
    runtime_topology_restored(rt, i);
  }
  return 0;
}

int ckpt_state_sim_time(const void *p, size_t len, double *sim_time) {
  state_blob_t b = {.p = (unsigned char *)p, .len = len, .cap = len};
  char name[SCENE_NAME_LEN];
  sb_get(&b, name, sizeof name);
  double t = sb_get_f64(&b);
  if (b.bad || !isfinite(t) || t < 0) return -1;
  *sim_time = t;
  return 0;
}

/* Refuses with `text`: -1. */
static int refuse(char *what, size_t whatlen, const char *text) {
  snprintf(what, whatlen, "%s", text);
  return -1;
}

int ckpt_state_get(state_blob_t *b, runtime_t *rt, const ckpt_session_io_t *io, char *what, size_t whatlen,
                   verr_t *err) {
  char name[SCENE_NAME_LEN];
  sb_get(b, name, sizeof name);
  name[SCENE_NAME_LEN - 1] = 0;
  if (strcmp(name, rt->scene.name)) return refuse(what, whatlen, "written for another scene");
  double sim_time = sb_get_f64(b);
  uint64_t steps = sb_get_u64(b);
  if (sb_get_u64(b) != rt->norgans) return refuse(what, whatlen, "organ count differs from the scene");
  /* First pass: check everything; only then change the runtime, so a bad
   * state leaves it untouched. */
  organ_at_t at[SCENE_MAX_ORGANS];
  for (size_t i = 0; i < rt->norgans; i++) {
    const model_t *m = rt->organs[i].model;
    size_t nn = sb_count(b, 48);
    uint64_t topo = sb_get_u64(b);
    if (b->bad) return refuse(what, whatlen, "truncated organ state (or a node count beyond the file)");
    if (topo == 0 && nn != m->nnodes)
      return refuse(what, whatlen, "node count differs from the scene's models (another organ mesh?)");
    if (topo > UINT32_MAX) return refuse(what, whatlen, "bad topology version");
    if (topo > 0 && !m->ops->restore_topology && !scalpel_owns_topology(rt, i)) {
      snprintf(what, whatlen, "organ '%s' changed its topology and its %s model cannot restore one",
               rt->organs[i].cfg->name, m->ops->name);
      return -1;
    }
    at[i] = (organ_at_t){.nnodes = nn, .topo = topo, .x = b->at, .v = b->at + 3 * nn * sizeof(double)};
    size_t bytes = 6 * nn * sizeof(double);
    for (size_t k = 0; k < 6 * nn; k++) {
      double v;
      memcpy(&v, b->p + b->at + k * sizeof v, sizeof v);
      if (!isfinite(v)) return refuse(what, whatlen, "non-finite organ state");
    }
    b->at += bytes;
    if (topo > 0) {
      at[i].nblob = sb_count(b, 1);
      at[i].blob = b->at;
      b->at += at[i].nblob;
      if (b->bad) return refuse(what, whatlen, "truncated topology data");
    }
  }
  if (sb_get_u64(b) != rt->ntools) return refuse(what, whatlen, "tool count differs from the scene");
  if (b->bad || !isfinite(sim_time) || sim_time < 0) return refuse(what, whatlen, "bad header values");
  for (size_t t = 0; t < rt->ntools; t++) {
    const char *bad = io && io->get_tool ? io->get_tool(io->ctx, b, t) : NULL;
    if (bad) return refuse(what, whatlen, bad);
  }
  if (sb_get_u64(b) != rt->ntasks) return refuse(what, whatlen, "task count differs from the scene");
  task_rt_t tasks[SCENE_MAX_TASKS];
  for (size_t k = 0; k < rt->ntasks; k++) {
    uint64_t started = sb_get_u64(b), completed = sb_get_u64(b);
    double t0 = sb_get_f64(b), t1 = sb_get_f64(b);
    if (b->bad || started > 1 || completed > started || !isfinite(t0) || !isfinite(t1) || t0 < 0 ||
        (completed && t1 < t0) || t0 > sim_time)
      return refuse(what, whatlen, "bad task state");
    tasks[k] = rt->tasks[k];
    tasks[k].started = (int)started;
    tasks[k].completed = (int)completed;
    tasks[k].t_start = t0;
    tasks[k].t_end = t1;
  }
  if (sb_get_u64(b) != rt->nstones) return refuse(what, whatlen, "object count differs from the scene");
  double stone_pos[SCENE_MAX_OBJECTS][3];
  int removed[SCENE_MAX_OBJECTS];
  for (size_t k = 0; k < rt->nstones; k++) {
    sb_get(b, stone_pos[k], sizeof stone_pos[k]);
    int64_t held = (int64_t)sb_get_u64(b);
    uint64_t rem = sb_get_u64(b);
    if (b->bad || !isfinite(stone_pos[k][0] + stone_pos[k][1] + stone_pos[k][2]) || held < -1 ||
        held >= (int64_t)rt->ntools || rem > 1)
      return refuse(what, whatlen, "bad object state");
    removed[k] = (int)rem;
  }
  const char *bad = io && io->get_tail ? io->get_tail(io->ctx, b) : NULL;
  if (bad) return refuse(what, whatlen, bad);
  if (b->bad || b->at != b->len) return refuse(what, whatlen, "truncated or trailing data");
  int rc = restore_topologies(rt, b, at, err);
  if (rc) return rc == -2 ? -2 : -3;
  for (size_t i = 0; i < rt->norgans; i++) {
    model_t *m = rt->organs[i].model;
    model_note_outside_write(m);
    if (at[i].topo > 0) continue; /* restore_topology took its positions */
    memcpy(m->x, b->p + at[i].x, 3 * m->nnodes * sizeof(double));
    memcpy(m->v, b->p + at[i].v, 3 * m->nnodes * sizeof(double));
    /* Positions written from outside: the tree's boxes fit them again
     * before anything queries it (proxies, the vertex culls). */
    aabb_tree_t *tree = &rt->organs[i].tree;
    if (tree->ntris && tree->x == m->surf_x && tree->nverts == m->nsurf) aabb_tree_refit(tree, m->surf_x);
  }
  memcpy(rt->tasks, tasks, rt->ntasks * sizeof tasks[0]);
  for (size_t k = 0; k < rt->nstones; k++) {
    stone_t *st = &rt->stones[k];
    memcpy(st->pos, stone_pos[k], sizeof st->pos);
    st->held_by = -1; /* tools re-enter from outside: a held stone is dropped where it was */
    st->removed = removed[k];
    memset(st->force, 0, sizeof st->force);
  }
  if (io && io->apply) io->apply(io->ctx);
  rt->sim_time = sim_time;
  rt->steps = steps;
  return 1;
}
