/* rec_tools: reads a session recording (rec_read.h) and prints, decoded
 * with the compiled-in descriptors, what the tool tests check (issue 4):
 *   EVENT KIND tool=N organ=N value=V TEXT       grasp and task SessionEvents
 *   TOOLMETRICS tool=N name=.. peak_force=.. ... last ToolMetrics per tool
 *   OBJECT id=N x= y= z= held_by= removed=       last ObjectState per object
 *   FEEDBACK_PAIRS n=.. min_tip_distance=..      ContactFeedback of tools 0
 *                                                and 1 at the same sim time
 *   VERTEX index=I max_dz=.. final_dz=..         with --vertex X Y Z: the
 *       organ-0 keyframe vertex nearest (X,Y,Z), its largest and its last
 *       z displacement over the recorded MeshDeltas (m)
 * Exit 1 when the file cannot be read, is damaged or a sample does not
 * decode.
 * usage: rec_tools FILE.db [--vertex X Y Z] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rec_read.h"
#include "viscera.h"

static recfile_t *rf;
static int bad;

/* Runs `fn` on every decoded sample of `topic` (see rec_read.h). */
static void each(const char *topic, const dds_topic_descriptor_t *desc, rec_decode_cb fn, void *ctx) {
  bad += rec_read_topic("rec_tools", rf, topic, desc, fn, ctx);
}

static const char *kind_name(viscera_EventKind k) {
  switch (k) {
  case viscera_EVENT_GRASP_BEGIN:
    return "GRASP_BEGIN";
  case viscera_EVENT_GRASP_END:
    return "GRASP_END";
  case viscera_EVENT_TASK_STARTED:
    return "TASK_STARTED";
  case viscera_EVENT_TASK_COMPLETED:
    return "TASK_COMPLETED";
  default:
    return NULL;
  }
}

static int on_event(void *ctx, const void *p, const recfile_row_t *row) {
  (void)row;
  (void)ctx;
  const viscera_SessionEvent *e = p;
  const char *k = kind_name(e->kind);
  if (k) printf("EVENT %s tool=%d organ=%d value=%.4f %s\n", k, (int)e->tool_id, (int)e->organ_id, e->value, e->text);
  return 0;
}

enum { MAXN = 8 };
static viscera_ToolMetrics tm[MAXN];
static int have_tm[MAXN];
static int on_tool_metrics(void *ctx, const void *p, const recfile_row_t *row) {
  (void)row;
  (void)ctx;
  const viscera_ToolMetrics *m = p;
  if (m->tool_id < MAXN) {
    tm[m->tool_id] = *m;
    have_tm[m->tool_id] = 1;
  }
  return 0;
}

static viscera_ObjectState ob[MAXN];
static int have_ob[MAXN];
static int on_object(void *ctx, const void *p, const recfile_row_t *row) {
  (void)row;
  (void)ctx;
  const viscera_ObjectState *o = p;
  if (o->object_id < MAXN) {
    ob[o->object_id] = *o;
    have_ob[o->object_id] = 1;
  }
  return 0;
}

/* ContactFeedback of tools 0 and 1: the tip each is told, matched by sim
 * time (both are published in the same step). */
typedef struct fb_pairs {
  unsigned long long t[2];
  float pos[2][3];
  int have[2];
  long n;
  double min_d;
} fb_pairs_t;
static int on_feedback(void *ctx, const void *p, const recfile_row_t *row) {
  (void)row;
  fb_pairs_t *fp = ctx;
  const viscera_ContactFeedback *f = p;
  if (f->tool_id > 1) return 0;
  int i = (int)f->tool_id;
  fp->t[i] = f->sim_time_ns;
  memcpy(fp->pos[i], f->proxy_position, sizeof fp->pos[i]);
  fp->have[i] = 1;
  if (fp->have[0] && fp->have[1] && fp->t[0] == fp->t[1]) {
    double d = 0;
    for (int k = 0; k < 3; k++) d += ((double)fp->pos[0][k] - fp->pos[1][k]) * ((double)fp->pos[0][k] - fp->pos[1][k]);
    d = sqrt(d);
    if (d < fp->min_d) fp->min_d = d;
    fp->n++;
  }
  return 0;
}

typedef struct vtrack {
  double at[3];
  long index; /* -1 until the keyframe */
  double key_z;
  double max_dz, final_dz;
  long deltas;
} vtrack_t;
static int on_state(void *ctx, const void *p, const recfile_row_t *row) {
  (void)row;
  vtrack_t *v = ctx;
  const viscera_MeshState *s = p;
  if (s->organ_id != 0 || v->index >= 0) return 0;
  double best = INFINITY;
  for (uint32_t i = 0; i + 2 < s->positions._length; i += 3) {
    double d = 0;
    for (int k = 0; k < 3; k++)
      d += (s->positions._buffer[i + k] - v->at[k]) * (s->positions._buffer[i + k] - v->at[k]);
    if (d < best) {
      best = d;
      v->index = i / 3;
      v->key_z = s->positions._buffer[i + 2];
    }
  }
  return 0;
}
static int on_delta(void *ctx, const void *p, const recfile_row_t *row) {
  (void)row;
  vtrack_t *v = ctx;
  const viscera_MeshDelta *d = p;
  if (d->organ_id != 0 || v->index < 0) return 0;
  double dz = 0;
  for (uint32_t j = 0; j < d->indices._length && 3 * j + 2 < d->dq._length; j++)
    if (d->indices._buffer[j] == (uint32_t)v->index) dz = d->dq._buffer[3 * j + 2] * (double)d->quant_step;
  if (dz > v->max_dz) v->max_dz = dz;
  v->final_dz = dz;
  v->deltas++;
  return 0;
}

int main(int argc, char **argv) {
  if (argc != 2 && !(argc == 6 && !strcmp(argv[2], "--vertex"))) {
    fprintf(stderr, "usage: rec_tools FILE.db [--vertex X Y Z]\n");
    return 2;
  }
  verr_t err;
  if (recfile_open(&rf, argv[1], &err) < 0) {
    fprintf(stderr, "rec_tools: %s\n", err.msg);
    return 1;
  }
  each("viscera_SessionEvent", &viscera_SessionEvent_desc, on_event, NULL);
  each("viscera_ToolMetrics", &viscera_ToolMetrics_desc, on_tool_metrics, NULL);
  each("viscera_ObjectState", &viscera_ObjectState_desc, on_object, NULL);
  fb_pairs_t fp = {.min_d = INFINITY};
  each("viscera_ContactFeedback", &viscera_ContactFeedback_desc, on_feedback, &fp);
  for (int i = 0; i < MAXN; i++)
    if (have_tm[i])
      printf("TOOLMETRICS tool=%d name=%s peak_force=%.4f contact_time=%.3f path_length=%.4f exploration_time=%.3f "
             "grasps=%u grasp_time=%.3f tasks_completed=%u tasks_total=%u operation_time=%.3f\n",
             i, tm[i].name, tm[i].peak_force, tm[i].contact_time, tm[i].path_length, tm[i].exploration_time,
             tm[i].grasps, tm[i].grasp_time, tm[i].tasks_completed, tm[i].tasks_total, tm[i].operation_time);
  for (int i = 0; i < MAXN; i++)
    if (have_ob[i])
      printf("OBJECT id=%d name=%s x=%.4f y=%.4f z=%.4f held_by=%d removed=%d\n", i, ob[i].name, ob[i].position[0],
             ob[i].position[1], ob[i].position[2], (int)ob[i].held_by, ob[i].removed ? 1 : 0);
  printf("FEEDBACK_PAIRS n=%ld min_tip_distance=%.6f\n", fp.n, fp.n ? fp.min_d : -1.0);
  if (argc == 6) {
    vtrack_t v = {.index = -1};
    for (int k = 0; k < 3; k++) v.at[k] = atof(argv[3 + k]);
    each("viscera_MeshState", &viscera_MeshState_desc, on_state, &v);
    each("viscera_MeshDelta", &viscera_MeshDelta_desc, on_delta, &v);
    printf("VERTEX index=%ld key_z=%.5f max_dz=%.5f final_dz=%.5f deltas=%ld\n", v.index, v.key_z, v.max_dz, v.final_dz,
           v.deltas);
  }
  recfile_close(rf);
  if (bad) fprintf(stderr, "rec_tools: %d samples or rows unreadable\n", bad);
  return bad ? 1 : 0;
}
