#include "resim/resim_run.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_delta.h"

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
} organ_buf_t;

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

static void compare_key(const runtime_t *rt, const resim_keyframe_t *key, const resim_hooks_t *hooks,
                        resim_result_t *res) {
  const model_t *m = rt->organs[key->organ].model;
  double ss;
  double mx = compare(m->surf_x, key->pos, m->nsurf, &ss);
  int exact = 1;
  for (size_t i = 0; i < 3 * m->nsurf && exact; i++) exact = (float)m->surf_x[i] == key->pos[i];
  resim_organ_result_t *r = &res->organs[key->organ];
  r->keyframes++;
  add_frame(r, key->step, mx, ss, m->nsurf, exact);
  if (hooks && hooks->frame)
    hooks->frame(hooks->arg, key->step, key->organ, 1, mx, m->nsurf ? sqrt(ss / (double)m->nsurf) : 0, exact);
}

static void compare_delta(const runtime_t *rt, const resim_recording_t *rec, const resim_delta_t *d, organ_buf_t *b,
                          const resim_hooks_t *hooks, resim_result_t *res) {
  const model_t *m = rt->organs[d->organ].model;
  resim_organ_result_t *r = &res->organs[d->organ];
  const resim_keyframe_t *key = find_key(rec, d->organ, d->keyframe_seq, d->topology_version);
  verr_t e;
  if (!key) {
    if (r->unmatched++ == 0 && !res->first_unmatched[0])
      snprintf(res->first_unmatched, sizeof res->first_unmatched,
               "organ %u frame %u (step %llu): keyframe %u was not recorded", d->organ, d->frame_seq,
               (unsigned long long)d->step, d->keyframe_seq);
    return;
  }
  if (mesh_delta_apply(key->pos, m->nsurf, d->quant, d->idx, d->count, d->dq, d->dq_len, b->mesh, &e)) {
    if (r->unmatched++ == 0 && !res->first_unmatched[0])
      snprintf(res->first_unmatched, sizeof res->first_unmatched, "organ %u frame %u (step %llu): %s", d->organ,
               d->frame_seq, (unsigned long long)d->step, e.msg);
    return;
  }
  double ss;
  double mx = compare(m->surf_x, b->mesh, m->nsurf, &ss);
  long n = mesh_delta_encode(key->pos, m->surf_x, m->nsurf, d->quant, b->idx, b->dq);
  int exact = n == (long)d->count && 3 * (size_t)n == d->dq_len &&
              (n == 0 || (memcmp(b->idx, d->idx, (size_t)n * sizeof *b->idx) == 0 &&
                          memcmp(b->dq, d->dq, 3 * (size_t)n * sizeof *b->dq) == 0));
  add_frame(r, d->step, mx, ss, m->nsurf, exact);
  if (hooks && hooks->frame)
    hooks->frame(hooks->arg, d->step, d->organ, 0, mx, m->nsurf ? sqrt(ss / (double)m->nsurf) : 0, exact);
}

int resim_run(runtime_t *rt, resim_recording_t *rec, const resim_hooks_t *hooks, resim_result_t *res, verr_t *err) {
  memset(res, 0, sizeof *res);
  uint64_t nsteps = rec->last_step;
  int32_t *sched[SCENE_MAX_TOOLS] = {0};
  organ_buf_t bufs[SCENE_MAX_ORGANS];
  memset(bufs, 0, sizeof bufs);
  int rc = 0;
  for (size_t t = 0; t < rt->ntools && !rc; t++) {
    sched[t] = malloc((nsteps + 1) * sizeof(int32_t));
    if (!sched[t]) {
      rc = verr_set(err, "out of memory for a %llu-step schedule", (unsigned long long)nsteps);
      break;
    }
    verr_t e;
    if (resim_schedule_build(&rec->tools[t], nsteps, sched[t], &res->sched[t], &e))
      rc = verr_set(err, "tool %zu ('%s'): %s", t, rt->tools[t].cfg->name, e.msg);
  }
  for (size_t i = 0; i < rt->norgans && !rc; i++) {
    size_t n = rt->organs[i].model->nsurf;
    bufs[i].mesh = malloc((3 * n + 1) * sizeof(float));
    bufs[i].idx = malloc((n + 1) * sizeof(uint32_t));
    bufs[i].dq = malloc((3 * n + 1) * sizeof(int16_t));
    if (!bufs[i].mesh || !bufs[i].idx || !bufs[i].dq) rc = verr_set(err, "out of memory for organ %zu", i);
  }
  if (!rc) {
    int32_t applied[SCENE_MAX_TOOLS];
    for (size_t t = 0; t < SCENE_MAX_TOOLS; t++) applied[t] = -1;
    size_t ki = 0, di = 0;
    uint64_t every = nsteps / 100 ? nsteps / 100 : 1;
    for (uint64_t k = 0; k <= nsteps; k++) {
      if (k > 0) {
        /* What read_commands did before this step. */
        for (size_t t = 0; t < rt->ntools; t++) {
          int32_t c = sched[t][k];
          if (c == applied[t]) continue;
          if (c < 0) {
            runtime_release_tool(rt, t);
          } else {
            const resim_cmd_t *cmd = &rec->tools[t].cmd[c];
            runtime_set_tool(rt, t, cmd->pos, cmd->max_force);
          }
          applied[t] = c;
        }
        res->rollbacks += (uint64_t)runtime_step(rt);
        res->steps++;
      }
      for (; ki < rec->nkeys && rec->keys[ki].step <= k; ki++)
        if (rec->keys[ki].step == k) compare_key(rt, &rec->keys[ki], hooks, res);
      for (; di < rec->ndeltas && rec->deltas[di].step <= k; di++)
        if (rec->deltas[di].step == k)
          compare_delta(rt, rec, &rec->deltas[di], &bufs[rec->deltas[di].organ], hooks, res);
      if (hooks && hooks->progress && k % every == 0) hooks->progress(hooks->arg, k, nsteps);
    }
  }
  for (size_t t = 0; t < SCENE_MAX_TOOLS; t++) free(sched[t]);
  for (size_t i = 0; i < SCENE_MAX_ORGANS; i++) {
    free(bufs[i].mesh);
    free(bufs[i].idx);
    free(bufs[i].dq);
  }
  return rc;
}
