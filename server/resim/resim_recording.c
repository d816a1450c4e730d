/* SPDX-License-Identifier: Apache-2.0 */
#include "resim/resim_recording.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "recording/recfile.h"
#include "recording/rec_decode.h"
#include "interaction/events.h"
#include "resim/resim_session.h"
#include "runtime/checkpoint_state.h"
#include "viscera.h"

typedef struct caps {
  size_t fb[SCENE_MAX_TOOLS], cmd[SCENE_MAX_TOOLS], rel[SCENE_MAX_TOOLS], keys, deltas;
  size_t inputs, events, objects, metrics;
} caps_t;

typedef struct load_ctx {
  resim_recording_t *rec;
  caps_t caps; /* allocated lengths of the arrays in rec */
  int oom;
  int64_t scene_ts; /* source timestamp of the earliest SceneInfo: the server's sim time 0 (0 unknown) */
  double start_s;   /* the sim time the session started at: a resumed one's checkpoint time, else 0 */
  /* Per object / tool: the last sample's sim time and epoch (a rebuild
   * restarts simulated time). */
  uint64_t obj_ns[SCENE_MAX_OBJECTS], met_ns[SCENE_MAX_TOOLS];
  uint32_t obj_epoch[SCENE_MAX_OBJECTS], met_epoch[SCENE_MAX_TOOLS];
  uint64_t seq_min, seq_max, seq_n; /* AppliedInput seqs seen (> 0) */
  /* Source timestamps (the server's clock) of the AppliedInput samples
   * that carried a rebuild, one entry per rebuild, in recording order. */
  int64_t *rebuild_ts;
  size_t nrebuild, caprebuild;
} load_ctx_t;

/* The epoch of a sample the server wrote at source time ts: the rebuilds
 * written before it (the AppliedInput of a rebuild is written after the
 * rebuild, before the step; every later sample is of the new epoch). */
static uint32_t epoch_at(const load_ctx_t *ctx, int64_t ts) {
  uint32_t e = 0;
  for (size_t i = 0; i < ctx->nrebuild; i++)
    if (ctx->rebuild_ts[i] <= ts) e++;
  return e;
}

static void skip(resim_recording_t *rec, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void skip(resim_recording_t *rec, const char *fmt, ...) {
  if (rec->skipped++ == 0) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(rec->first_skip, sizeof rec->first_skip, fmt, ap);
    va_end(ap);
  }
}

/* Grows *arr (element size `size`) to hold one more; 0 or -1 (out of memory). */
static int grow(void **arr, size_t *cap, size_t n, size_t size) {
  if (n < *cap) return 0;
  size_t nc = *cap ? 2 * *cap : 64;
  void *p = realloc(*arr, nc * size);
  if (!p) return -1;
  *arr = p;
  *cap = nc;
  return 0;
}

/* The server step of a sim time; UINT64_MAX beyond RESIM_MAX_SIM_S, or
 * beyond the recording's own span: the server stamps a sample of sim time
 * t no earlier than t after it wrote its SceneInfo (sim time 0; it never
 * runs ahead of the wall clock), so a sim time later than the sample's own
 * source timestamp minus the SceneInfo's, plus RESIM_SPAN_SLACK_S, is
 * garbled (one flipped bit in a MeshDelta header planned 17.6 million
 * steps). Both timestamps come from the server's clock. A session resumed
 * from a checkpoint starts at the checkpoint's sim time (SceneSource's
 * resume state), not 0: its span starts there. */
static uint64_t step_of(const load_ctx_t *ctx, const recfile_row_t *row, uint64_t sim_time_ns) {
  const resim_recording_t *rec = ctx->rec;
  double s = (double)sim_time_ns * 1e-9;
  if (s > RESIM_MAX_SIM_S) return UINT64_MAX;
  if (ctx->scene_ts > 0 && row->source_ts_ns > 0) {
    double span = (double)(row->source_ts_ns - ctx->scene_ts) * 1e-9 + ctx->start_s + RESIM_SPAN_SLACK_S;
    if (s > span) return UINT64_MAX;
  }
  return (uint64_t)llround(s / rec->dt);
}

static int on_scene(void *arg, const void *sample, const recfile_row_t *row) {
  resim_recording_t *rec = ((load_ctx_t *)arg)->rec;
  const viscera_SceneInfo *si = sample;
  if (!(si->physics_dt > 0 && si->physics_dt < 1) || si->organs._length > SCENE_MAX_ORGANS ||
      si->tools._length > SCENE_MAX_TOOLS || !(si->quant_step > 0)) {
    skip(rec,
         "SceneInfo sample %lld: dt %g, %u organs, %u tools, quant_step %g beyond the recording (RESIM_MAX_SIM_S or "
         "its own span)",
         (long long)row->id, si->physics_dt, si->organs._length, si->tools._length, (double)si->quant_step);
  } else {
    rec->have_scene = 1;
    load_ctx_t *ctx = arg;
    if (row->source_ts_ns > 0 && (ctx->scene_ts == 0 || row->source_ts_ns < ctx->scene_ts))
      ctx->scene_ts = row->source_ts_ns;
    snprintf(rec->scene, sizeof rec->scene, "%s", si->scene);
    rec->dt = si->physics_dt;
    rec->publish_hz = si->publish_hz;
    rec->quant_step = si->quant_step;
    rec->norgans = si->organs._length;
    rec->ntools = si->tools._length;
    for (uint32_t i = 0; i < si->organs._length; i++) {
      snprintf(rec->organs[i].name, sizeof rec->organs[i].name, "%s", si->organs._buffer[i].name);
      rec->organs[i].nverts = si->organs._buffer[i].vertex_count;
      rec->organs[i].ntris = si->organs._buffer[i].triangle_count;
    }
  }
  return 0;
}

static int on_command(void *arg, const void *sample, const recfile_row_t *row) {
  load_ctx_t *ctx = arg;
  resim_recording_t *rec = ctx->rec;
  const viscera_ToolCommand *c = sample;
  if (c->tool_id >= rec->ntools) {
    skip(rec, "ToolCommand sample %lld: tool %u not in the scene", (long long)row->id, c->tool_id);
    return 0;
  }
  resim_tool_input_t *t = &rec->tools[c->tool_id];
  if (grow((void **)&t->cmd, &ctx->caps.cmd[c->tool_id], t->ncmd, sizeof *t->cmd)) return ctx->oom = 1;
  resim_cmd_t *o = &t->cmd[t->ncmd++];
  o->seq = c->seq;
  o->wall_ns = row->source_ts_ns;
  for (int k = 0; k < 3; k++) o->pos[k] = c->position[k];
  o->max_force = c->max_force;
  return 0;
}

static int on_feedback(void *arg, const void *sample, const recfile_row_t *row) {
  load_ctx_t *ctx = arg;
  resim_recording_t *rec = ctx->rec;
  const viscera_ContactFeedback *f = sample;
  if (f->tool_id >= rec->ntools) {
    skip(rec, "ContactFeedback sample %lld: tool %u not in the scene", (long long)row->id, f->tool_id);
    return 0;
  }
  uint64_t step = step_of(ctx, row, f->sim_time_ns);
  if (step == UINT64_MAX) {
    skip(rec, "ContactFeedback sample %lld: sim time %llu ns beyond the recording (RESIM_MAX_SIM_S or its own span)",
         (long long)row->id, (unsigned long long)f->sim_time_ns);
    return 0;
  }
  resim_tool_input_t *t = &rec->tools[f->tool_id];
  if (grow((void **)&t->fb, &ctx->caps.fb[f->tool_id], t->nfb, sizeof *t->fb)) return ctx->oom = 1;
  t->fb[t->nfb++] = (resim_fb_t){.step = step, .seq = f->cmd_seq, .wall_ns = row->source_ts_ns};
  return 0;
}

/* The interaction events (grasp, task, cut) a re-simulated runtime reports
 * too, with their step. 0, or -1 out of memory. */
static int collect_event(load_ctx_t *ctx, const viscera_SessionEvent *e, const recfile_row_t *row) {
  resim_recording_t *rec = ctx->rec;
  int kind;
  switch (e->kind) {
  case viscera_EVENT_GRASP_BEGIN:
    kind = IEV_GRASP_BEGIN;
    break;
  case viscera_EVENT_GRASP_END:
    kind = IEV_GRASP_END;
    break;
  case viscera_EVENT_TASK_STARTED:
    kind = IEV_TASK_STARTED;
    break;
  case viscera_EVENT_TASK_COMPLETED:
    kind = IEV_TASK_COMPLETED;
    break;
  case viscera_EVENT_CUT_BEGIN:
    kind = IEV_CUT_BEGIN;
    break;
  case viscera_EVENT_CUT_END:
    kind = IEV_CUT_END;
    break;
  default:
    return 0;
  }
  uint64_t step = step_of(ctx, row, e->sim_time_ns);
  if (step == UINT64_MAX) {
    skip(rec, "SessionEvent sample %lld: sim time %llu ns out of range", (long long)row->id,
         (unsigned long long)e->sim_time_ns);
    return 0;
  }
  if (grow((void **)&rec->events, &ctx->caps.events, rec->nevents, sizeof *rec->events)) return -1;
  rec->events[rec->nevents++] =
      (resim_event_t){.kind = kind, .tool = e->tool_id, .organ = e->organ_id, .value = e->value, .step = step};
  return 0;
}

static int on_event(void *arg, const void *sample, const recfile_row_t *row) {
  load_ctx_t *ctx = arg;
  resim_recording_t *rec = ctx->rec;
  const viscera_SessionEvent *e = sample;
  if (e->source_id == 0 && collect_event(ctx, e, row)) return ctx->oom = 1;
  if (e->kind != viscera_EVENT_CLIENT_LOST) return 0;
  if (e->tool_id < 0 || (size_t)e->tool_id >= rec->ntools) {
    skip(rec, "SessionEvent sample %lld: CLIENT_LOST for tool %d not in the scene", (long long)row->id,
         (int)e->tool_id);
    return 0;
  }
  uint64_t step = step_of(ctx, row, e->sim_time_ns);
  if (step == UINT64_MAX) {
    skip(rec, "SessionEvent sample %lld: sim time %llu ns beyond the recording (RESIM_MAX_SIM_S or its own span)",
         (long long)row->id, (unsigned long long)e->sim_time_ns);
    return 0;
  }
  resim_tool_input_t *t = &rec->tools[e->tool_id];
  if (grow((void **)&t->release, &ctx->caps.rel[e->tool_id], t->nrelease, sizeof *t->release)) return ctx->oom = 1;
  t->release[t->nrelease++] = step;
  return 0;
}

static int on_state(void *arg, const void *sample, const recfile_row_t *row) {
  load_ctx_t *ctx = arg;
  resim_recording_t *rec = ctx->rec;
  const viscera_MeshState *s = sample;
  int rc = 0;
  if (step_of(ctx, row, s->sim_time_ns) == UINT64_MAX) {
    skip(rec, "MeshState sample %lld: sim time %llu ns beyond the recording (RESIM_MAX_SIM_S or its own span)",
         (long long)row->id, (unsigned long long)s->sim_time_ns);
  } else if (s->organ_id >= rec->norgans) {
    skip(rec, "MeshState sample %lld: organ %u not in the scene", (long long)row->id, s->organ_id);
  } else if (s->positions._length % 3 || s->triangles._length % 3 || s->positions._length > 3u * RESIM_MAX_VERTS) {
    skip(rec,
         "MeshState sample %lld: organ %u has %u coordinates and %u triangle indices, not whole vertices and "
         "triangles",
         (long long)row->id, s->organ_id, s->positions._length, s->triangles._length);
  } else if (grow((void **)&rec->keys, &ctx->caps.keys, rec->nkeys, sizeof *rec->keys)) {
    rc = ctx->oom = 1;
  } else {
    float *pos = malloc(s->positions._length * sizeof(float) + 1);
    uint32_t *tris = malloc(s->triangles._length * sizeof(uint32_t) + 1);
    if (!pos || !tris) {
      free(pos);
      free(tris);
      rc = ctx->oom = 1;
    } else {
      if (s->positions._length) memcpy(pos, s->positions._buffer, s->positions._length * sizeof(float));
      if (s->triangles._length) memcpy(tris, s->triangles._buffer, s->triangles._length * sizeof(uint32_t));
      rec->keys[rec->nkeys++] = (resim_keyframe_t){.organ = s->organ_id,
                                                   .keyframe_seq = s->keyframe_seq,
                                                   .topology_version = s->topology_version,
                                                   .step = step_of(ctx, row, s->sim_time_ns),
                                                   .nverts = s->positions._length / 3,
                                                   .ntris = s->triangles._length / 3,
                                                   .pos = pos,
                                                   .tris = tris};
    }
  }
  return rc;
}

static int on_delta(void *arg, const void *sample, const recfile_row_t *row) {
  load_ctx_t *ctx = arg;
  resim_recording_t *rec = ctx->rec;
  const viscera_MeshDelta *d = sample;
  int rc = 0;
  if (step_of(ctx, row, d->sim_time_ns) == UINT64_MAX) {
    skip(rec, "MeshDelta sample %lld: sim time %llu ns beyond the recording (RESIM_MAX_SIM_S or its own span)",
         (long long)row->id, (unsigned long long)d->sim_time_ns);
  } else if (d->organ_id >= rec->norgans) {
    skip(rec, "MeshDelta sample %lld: organ %u not in the scene", (long long)row->id, d->organ_id);
  } else if (grow((void **)&rec->deltas, &ctx->caps.deltas, rec->ndeltas, sizeof *rec->deltas)) {
    rc = ctx->oom = 1;
  } else {
    /* Lengths are checked against each other and the mesh when applied
     * (mesh_delta_apply); here they are only copied. */
    uint32_t *idx = malloc(d->indices._length * sizeof(uint32_t) + 1);
    int16_t *dq = malloc(d->dq._length * sizeof(int16_t) + 1);
    if (!idx || !dq) {
      free(idx);
      free(dq);
      rc = ctx->oom = 1;
    } else {
      if (d->indices._length) memcpy(idx, d->indices._buffer, d->indices._length * sizeof(uint32_t));
      if (d->dq._length) memcpy(dq, d->dq._buffer, d->dq._length * sizeof(int16_t));
      rec->deltas[rec->ndeltas++] = (resim_delta_t){.organ = d->organ_id,
                                                    .keyframe_seq = d->keyframe_seq,
                                                    .topology_version = d->topology_version,
                                                    .frame_seq = d->frame_seq,
                                                    .step = step_of(ctx, row, d->sim_time_ns),
                                                    .quant = d->quant_step,
                                                    .count = d->indices._length,
                                                    .idx = idx,
                                                    .dq = dq,
                                                    .dq_len = d->dq._length};
    }
  }
  return rc;
}

/* One AppliedInput sample: its tool entries, then its controls, each with
 * the sample's header. */
static int on_applied(void *arg, const void *sample, const recfile_row_t *row) {
  load_ctx_t *ctx = arg;
  resim_recording_t *rec = ctx->rec;
  const viscera_AppliedInput *a = sample;
  resim_input_t h = {.tick = a->tick, .step = a->step, .epoch = a->epoch};
  if (a->seq > 0) {
    if (!ctx->seq_n || a->seq < ctx->seq_min) ctx->seq_min = a->seq;
    if (!ctx->seq_n || a->seq > ctx->seq_max) ctx->seq_max = a->seq;
    ctx->seq_n++;
  }
  if ((double)a->step * rec->dt > RESIM_MAX_SIM_S) {
    skip(rec, "AppliedInput sample %lld: step %llu out of range", (long long)row->id, (unsigned long long)a->step);
    return 0;
  }
  for (uint32_t i = 0; i < a->tools._length; i++) {
    const viscera_AppliedTool *t = &a->tools._buffer[i];
    if (t->tool_id >= rec->ntools) {
      skip(rec, "AppliedInput sample %lld: tool %u not in the scene", (long long)row->id, t->tool_id);
      continue;
    }
    if (grow((void **)&rec->inputs, &ctx->caps.inputs, rec->ninputs, sizeof *rec->inputs)) return ctx->oom = 1;
    resim_input_t *in = &rec->inputs[rec->ninputs++];
    *in = h;
    in->kind = t->released ? RESIM_IN_RELEASE : RESIM_IN_COMMAND;
    in->tool = t->tool_id;
    for (int k = 0; k < 3; k++) in->cmd.pos[k] = t->position[k];
    for (int k = 0; k < 4; k++) in->cmd.q[k] = t->orientation[k];
    in->cmd.buttons = t->buttons;
    in->cmd.max_force = t->max_force;
    in->cmd.seq = t->cmd_seq;
    in->cmd.echo = t->cmd_client_mono_ns;
  }
  for (uint32_t i = 0; i < a->controls._length; i++) {
    const viscera_AppliedControl *c = &a->controls._buffer[i];
    if (grow((void **)&rec->inputs, &ctx->caps.inputs, rec->ninputs, sizeof *rec->inputs)) return ctx->oom = 1;
    resim_input_t *in = &rec->inputs[rec->ninputs++];
    *in = h;
    in->kind = RESIM_IN_CONTROL;
    in->control = (int)c->kind;
    in->ctl_tool = c->tool_id;
    in->ctl_organ = c->organ_id;
    memcpy(in->values, c->values, sizeof in->values);
    in->result = c->result;
    in->task = c->task;
    if ((c->kind == viscera_CONTROL_RESET || c->kind == viscera_CONTROL_SET_MATERIAL) &&
        (c->result == 1 || c->result == 2)) {
      if (grow((void **)&ctx->rebuild_ts, &ctx->caprebuild, ctx->nrebuild, sizeof *ctx->rebuild_ts))
        return ctx->oom = 1;
      ctx->rebuild_ts[ctx->nrebuild++] = row->source_ts_ns;
    }
  }
  return 0;
}

static int on_object(void *arg, const void *sample, const recfile_row_t *row) {
  load_ctx_t *ctx = arg;
  resim_recording_t *rec = ctx->rec;
  const viscera_ObjectState *o = sample;
  uint64_t step = step_of(ctx, row, o->sim_time_ns);
  if (o->object_id >= SCENE_MAX_OBJECTS || step == UINT64_MAX) {
    skip(rec, "ObjectState sample %lld: object %u or sim time out of range", (long long)row->id, o->object_id);
    return 0;
  }
  /* Without recorded inputs (an older recording), a rebuild shows as the
   * object's simulated time going back. */
  if (o->sim_time_ns < ctx->obj_ns[o->object_id]) ctx->obj_epoch[o->object_id]++;
  ctx->obj_ns[o->object_id] = o->sim_time_ns;
  if (rec->ninputs) ctx->obj_epoch[o->object_id] = epoch_at(ctx, row->source_ts_ns);
  if (grow((void **)&rec->objects, &ctx->caps.objects, rec->nobjects, sizeof *rec->objects)) return ctx->oom = 1;
  rec->objects[rec->nobjects++] = (resim_object_t){.object = o->object_id,
                                                   .epoch = ctx->obj_epoch[o->object_id],
                                                   .step = step,
                                                   .pos = {o->position[0], o->position[1], o->position[2]},
                                                   .held_by = o->held_by,
                                                   .removed = o->removed};
  return 0;
}

static int on_metrics(void *arg, const void *sample, const recfile_row_t *row) {
  load_ctx_t *ctx = arg;
  resim_recording_t *rec = ctx->rec;
  const viscera_ToolMetrics *m = sample;
  uint64_t step = step_of(ctx, row, m->sim_time_ns);
  if (m->tool_id >= rec->ntools || step == UINT64_MAX) {
    skip(rec, "ToolMetrics sample %lld: tool %u or sim time out of range", (long long)row->id, m->tool_id);
    return 0;
  }
  if (m->sim_time_ns < ctx->met_ns[m->tool_id]) ctx->met_epoch[m->tool_id]++;
  ctx->met_ns[m->tool_id] = m->sim_time_ns;
  if (rec->ninputs) ctx->met_epoch[m->tool_id] = epoch_at(ctx, row->source_ts_ns);
  if (grow((void **)&rec->metrics, &ctx->caps.metrics, rec->nmetrics, sizeof *rec->metrics)) return ctx->oom = 1;
  rec->metrics[rec->nmetrics++] =
      (resim_tool_metrics_t){.tool = m->tool_id,
                             .epoch = ctx->met_epoch[m->tool_id],
                             .step = step,
                             .peak_force = m->peak_force,
                             .time_above = {m->time_above_st, m->time_above_mpf, m->time_above_sft},
                             .contact_time = m->contact_time,
                             .path_length = m->path_length,
                             .grasp_time = m->grasp_time,
                             .operation_time = m->operation_time,
                             .grasps = m->grasps,
                             .tasks_completed = m->tasks_completed};
  return 0;
}

static int on_source(void *arg, const void *sample, const recfile_row_t *row) {
  (void)row;
  load_ctx_t *ctx = arg;
  resim_source_t *src = &ctx->rec->source;
  const viscera_SceneSource *s = sample;
  char *text = strdup(s->text ? s->text : "");
  unsigned char *resume = s->resume_state._length ? malloc(s->resume_state._length) : NULL;
  if (!text || (s->resume_state._length && !resume)) {
    free(text);
    return ((load_ctx_t *)arg)->oom = 1;
  }
  if (resume) memcpy(resume, s->resume_state._buffer, s->resume_state._length);
  /* An unreadable start time leaves the span from 0: resim_resume names
   * what is wrong with the state. */
  double t0 = 0;
  ctx->start_s =
      resume && ckpt_state_sim_time(resume, s->resume_state._length, &t0) == 0 && t0 <= RESIM_MAX_SIM_S ? t0 : 0;
  free(src->text);
  free(src->resume);
  memset(src, 0, sizeof *src);
  src->have = 1;
  src->text = text;
  src->resume = resume;
  src->resume_len = s->resume_state._length;
  snprintf(src->resume_sha256, sizeof src->resume_sha256, "%s", s->resume_sha256);
  snprintf(src->path, sizeof src->path, "%s", s->path);
  snprintf(src->text_sha256, sizeof src->text_sha256, "%s", s->text_sha256);
  for (uint32_t i = 0; i < s->meshes._length && i < SCENE_MAX_ORGANS; i++) {
    snprintf(src->meshes[i].path, sizeof src->meshes[i].path, "%s", s->meshes._buffer[i].path);
    snprintf(src->meshes[i].sha256, sizeof src->meshes[i].sha256, "%s", s->meshes._buffer[i].sha256);
    src->meshes[i].size = s->meshes._buffer[i].size;
    src->nmeshes = i + 1;
  }
  snprintf(src->version, sizeof src->version, "%s", s->version);
  snprintf(src->compiler, sizeof src->compiler, "%s", s->compiler);
  snprintf(src->build_flags, sizeof src->build_flags, "%s", s->build_flags);
  snprintf(src->station, sizeof src->station, "%s", s->station);
  return 0;
}

static int cmp_key(const void *a, const void *b) {
  const resim_keyframe_t *x = a, *y = b;
  if (x->step != y->step) return x->step < y->step ? -1 : 1;
  if (x->organ != y->organ) return x->organ < y->organ ? -1 : 1;
  return x->keyframe_seq < y->keyframe_seq ? -1 : x->keyframe_seq > y->keyframe_seq;
}

static int cmp_delta(const void *a, const void *b) {
  const resim_delta_t *x = a, *y = b;
  if (x->step != y->step) return x->step < y->step ? -1 : 1;
  if (x->organ != y->organ) return x->organ < y->organ ? -1 : 1;
  return x->frame_seq < y->frame_seq ? -1 : x->frame_seq > y->frame_seq;
}

typedef struct topic_pass {
  const char *name;
  const dds_topic_descriptor_t *desc;
  rec_decode_cb cb;
  uint64_t *count; /* data samples read, decodable or not; NULL: not counted */
} topic_pass_t;

/* Samples that do not decode are skipped like out-of-range ones: counted,
 * the first one named. */
static void skip_undecodable(resim_recording_t *rec, const char *topic, const rec_decode_report_t *rep) {
  if (!rep->undecodable) return;
  skip(rec, "%s sample %lld does not decode (%llu in all)", topic + strlen("viscera_"),
       (long long)rep->first_undecodable, (unsigned long long)rep->undecodable);
  rec->skipped += rep->undecodable - 1;
}

/* A topic pass restricted to the chosen session's writers. */
typedef struct session_filter {
  const resim_session_t *session;
  rec_decode_cb cb;
  void *arg;
  uint64_t kept; /* samples of the session passed on */
} session_filter_t;

static int in_session(void *arg, const void *sample, const recfile_row_t *row) {
  session_filter_t *f = arg;
  if (!resim_session_has(f->session, row->writer_id)) return 0;
  f->kept++;
  return f->cb(f->arg, sample, row);
}

int resim_recording_load(resim_recording_t *rec, const char *path, const char *partition, size_t run, verr_t *err) {
  memset(rec, 0, sizeof *rec);
  recfile_t *rf = NULL;
  if (recfile_open(&rf, path, err)) return -1;
  resim_session_t session;
  if (resim_session_pick(rf, partition, run, &session, err)) {
    verr_t e = *err;
    verr_set(err, "%s: %s", path, e.msg);
    recfile_close(rf);
    return -1;
  }
  snprintf(rec->partition, sizeof rec->partition, "%s", session.partition);
  rec->nruns = session.nruns;
  rec->run = session.run;
  snprintf(rec->warnings, sizeof rec->warnings, "%s", recfile_warnings(rf));
  load_ctx_t ctx = {.rec = rec};
  /* SceneInfo first: dt turns every sim time into a step, and the organ and
   * tool counts bound every other sample; then SceneSource: a resumed
   * session's start time bounds the sim times. */
  const topic_pass_t passes[] = {
      {"viscera_SceneInfo", &viscera_SceneInfo_desc, on_scene, NULL},
      {"viscera_SceneSource", &viscera_SceneSource_desc, on_source, NULL},
      {"viscera_ToolCommand", &viscera_ToolCommand_desc, on_command, &rec->n_commands},
      {"viscera_ContactFeedback", &viscera_ContactFeedback_desc, on_feedback, &rec->n_feedback},
      {"viscera_SessionEvent", &viscera_SessionEvent_desc, on_event, &rec->n_events},
      {"viscera_MeshState", &viscera_MeshState_desc, on_state, &rec->n_states},
      {"viscera_MeshDelta", &viscera_MeshDelta_desc, on_delta, &rec->n_deltas},
      {"viscera_AppliedInput", &viscera_AppliedInput_desc, on_applied, &rec->n_applied},
      {"viscera_ObjectState", &viscera_ObjectState_desc, on_object, &rec->n_objects},
      {"viscera_ToolMetrics", &viscera_ToolMetrics_desc, on_metrics, &rec->n_metrics},
  };
  int rc = 0;
  for (size_t p = 0; p < sizeof passes / sizeof passes[0] && !rc; p++) {
    rec_decode_report_t rep;
    session_filter_t f = {&session, passes[p].cb, &ctx, 0};
    if (rec_decode_topic(rf, passes[p].name, passes[p].desc, in_session, &f, &rep) < 0) ctx.oom = 1;
    if (rep.topic_missing) {
      if (p == 0) rc = verr_set(err, "%s: no SceneInfo topic recorded: cannot tell which scene this is", path);
      continue; /* e.g. no tool ever connected: nothing to schedule */
    }
    /* (undecodable samples are counted whichever session wrote them) */
    if (passes[p].count) *passes[p].count = f.kept + rep.undecodable;
    skip_undecodable(rec, passes[p].name, &rep);
    if (ctx.oom)
      rc = verr_set(err, "%s: out of memory reading %s", path, passes[p].name);
    else if (rep.scan.damaged && !rec->warnings[0])
      snprintf(rec->warnings, sizeof rec->warnings, "%s: damaged while reading %s: %s", path, passes[p].name,
               rep.scan.first_error);
    if (p == 0 && !rc && !rec->have_scene)
      rc = verr_set(err, "%s: no SceneInfo sample decodes%s%s%s%s", path, rec->skipped ? ": " : "", rec->first_skip,
                    rep.scan.damaged ? "; the file is damaged: " : "", rep.scan.damaged ? rep.scan.first_error : "");
  }
  recfile_close(rf);
  resim_session_free(&session);
  free(ctx.rebuild_ts);
  /* The server numbers its samples from 1: a missing one is a lost input
   * (duplicates, which a reliable reader does not deliver, would hide one;
   * more samples than numbers can only be duplicates, not a negative loss). */
  if (ctx.seq_n && ctx.seq_max > ctx.seq_n) rec->applied_lost = ctx.seq_max - ctx.seq_n;
  if (rc) {
    resim_recording_free(rec);
    return -1;
  }
  if (rec->nkeys) qsort(rec->keys, rec->nkeys, sizeof *rec->keys, cmp_key);
  if (rec->ndeltas) qsort(rec->deltas, rec->ndeltas, sizeof *rec->deltas, cmp_delta);
  for (size_t i = 0; i < rec->nkeys; i++)
    rec->last_step = rec->keys[i].step > rec->last_step ? rec->keys[i].step : rec->last_step;
  for (size_t i = 0; i < rec->ndeltas; i++)
    rec->last_step = rec->deltas[i].step > rec->last_step ? rec->deltas[i].step : rec->last_step;
  return 0;
}

void resim_recording_free(resim_recording_t *rec) {
  for (size_t t = 0; t < SCENE_MAX_TOOLS; t++) {
    free(rec->tools[t].fb);
    free(rec->tools[t].cmd);
    free(rec->tools[t].release);
  }
  for (size_t i = 0; i < rec->nkeys; i++) {
    free(rec->keys[i].pos);
    free(rec->keys[i].tris);
  }
  free(rec->inputs);
  free(rec->events);
  free(rec->objects);
  free(rec->metrics);
  free(rec->source.text);
  free(rec->source.resume);
  for (size_t i = 0; i < rec->ndeltas; i++) {
    free(rec->deltas[i].idx);
    free(rec->deltas[i].dq);
  }
  free(rec->keys);
  free(rec->deltas);
  memset(rec, 0, sizeof *rec);
}
