/* SPDX-License-Identifier: Apache-2.0 */
/* resim_run (server/resim/resim_run.h) without DDS: a reference run of the default
 * scene (probe pressed 8 mm into the kidney, held, released) writes its
 * frames as the server's publisher encodes them, with one feedback per step
 * and the release, into a resim_recording_t; a fresh runtime must reproduce
 * every frame bit for bit, a runtime with the kidney twice as stiff must
 * not, and a scene with another name is refused. Needs VISCERA_SOURCE_DIR. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "test_runtime.h"
#include "resim/resim_run.h"
#include "session/mesh_publisher.h"

enum { N = 420, PUBLISH_EVERY = 33, RELEASE_AT = 330 };

static int add_key(resim_recording_t *rec, const mesh_publisher_t *mp, uint64_t step) {
  resim_keyframe_t *k = &rec->keys[rec->nkeys++];
  k->organ = 0;
  k->keyframe_seq = mp->keyframe_seq;
  k->topology_version = mp->topology_version;
  k->step = step;
  k->pos = malloc(3 * mp->nverts * sizeof(float));
  if (!k->pos) return -1;
  memcpy(k->pos, mp->key, 3 * mp->nverts * sizeof(float));
  return 0;
}

/* Runs the scene's reference session and records it. */
static int record(const scene_t *sc, resim_recording_t *rec) {
  static runtime_t rt;
  verr_t e;
  if (runtime_init(&rt, sc, &e)) {
    fprintf(stderr, "%s\n", e.msg);
    return -1;
  }
  const model_t *m = rt.organs[0].model;
  memset(rec, 0, sizeof *rec);
  rec->have_scene = 1;
  snprintf(rec->scene, sizeof rec->scene, "%s", sc->name);
  rec->dt = sc->dt;
  rec->quant_step = (float)sc->quant_step;
  rec->norgans = 1;
  rec->ntools = 1;
  snprintf(rec->organs[0].name, sizeof rec->organs[0].name, "%s", sc->organs[0].name);
  rec->organs[0].nverts = (uint32_t)m->nsurf;
  rec->organs[0].ntris = (uint32_t)m->nsurf_tris;
  resim_tool_input_t *t = &rec->tools[0];
  t->cmd = calloc(N + 1, sizeof *t->cmd);
  t->fb = calloc(N + 1, sizeof *t->fb);
  t->release = calloc(1, sizeof *t->release);
  rec->keys = calloc(N / PUBLISH_EVERY + 8, sizeof *rec->keys);
  rec->deltas = calloc(N / PUBLISH_EVERY + 8, sizeof *rec->deltas);
  mesh_publisher_t mp;
  if (!t->cmd || !t->fb || !t->release || !rec->keys || !rec->deltas ||
      mesh_publisher_init(&mp, 0, m->nsurf, m->surf_tris, m->nsurf_tris, (float)sc->quant_step, 0, 0, &e)) {
    runtime_destroy(&rt);
    return -1;
  }
  double lo[3], hi[3];
  mesh_bounds(&rt.organs[0].rest, lo, hi);
  mesh_publisher_keyframe(&mp, m->surf_x, 0);
  int rc = add_key(rec, &mp, 0);
  for (uint64_t k = 1; k <= N && !rc; k++) {
    if (k <= RELEASE_AT) {
      /* Down from 5 mm above the top to 8 mm in over 200 steps, then hold;
       * positions as the wire carries them (float). */
      double a = k < 200 ? (double)k / 200.0 : 1.0;
      resim_cmd_t *c = &t->cmd[t->ncmd++];
      c->seq = k;
      c->wall_ns = (int64_t)k * 1000000;
      c->max_force = (float)4.0;
      c->pos[0] = (float)(0.5 * (lo[0] + hi[0]));
      c->pos[1] = (float)(0.5 * (lo[1] + hi[1]));
      c->pos[2] = (float)(hi[2] + 0.005 - a * 0.013);
      runtime_set_tool(&rt, 0, c->pos, c->max_force);
      t->fb[t->nfb++] = (resim_fb_t){.step = k, .seq = k, .wall_ns = (int64_t)k * 1000000 + 400000};
    } else if (k == RELEASE_AT + 1) {
      runtime_release_tool(&rt, 0);
      t->release[t->nrelease++] = RELEASE_AT;
    }
    runtime_step(&rt);
    if (k % PUBLISH_EVERY == 0 || k == N) {
      int keyed = mesh_publisher_frame(&mp, m->surf_x, k * 1000000);
      if (keyed == 1) rc = add_key(rec, &mp, k);
      resim_delta_t *d = &rec->deltas[rec->ndeltas++];
      size_t n = (size_t)(mp.last_count > 0 ? mp.last_count : 0);
      *d = (resim_delta_t){.organ = 0,
                           .keyframe_seq = mp.keyframe_seq,
                           .frame_seq = mp.frame_seq,
                           .step = k,
                           .quant = mp.quant,
                           .count = (uint32_t)n,
                           .dq_len = 3 * n};
      d->idx = malloc(n * sizeof(uint32_t) + 1);
      d->dq = malloc(3 * n * sizeof(int16_t) + 1);
      if (!d->idx || !d->dq)
        rc = -1;
      else {
        memcpy(d->idx, mp.idx, n * sizeof(uint32_t));
        memcpy(d->dq, mp.dq, 3 * n * sizeof(int16_t));
      }
    }
  }
  rec->last_step = N;
  printf("reference: peak force %.3f N\n", rt.tools[0].peak_force);
  CHECK(rt.tools[0].peak_force > 0.5); /* the press really dented the kidney */
  mesh_publisher_destroy(&mp);
  runtime_destroy(&rt);
  return rc;
}

static int resim(const scene_t *sc, resim_recording_t *rec, resim_result_t *res) {
  static runtime_t rt;
  verr_t e;
  if (runtime_init(&rt, sc, &e) || resim_check_scene(&rt, rec, &e) || resim_run(&rt, rec, NULL, res, &e)) {
    fprintf(stderr, "%s\n", e.msg);
    runtime_destroy(&rt);
    return -1;
  }
  runtime_destroy(&rt);
  return 0;
}

int main(void) {
  const char *src = getenv("VISCERA_SOURCE_DIR");
  if (!src) {
    fprintf(stderr, "test_resim_run: VISCERA_SOURCE_DIR not set\n");
    return 77;
  }
  static scene_t sc;
  verr_t e;
  if (!test_runtime_load_scene(NULL, &sc, "default.yaml", &e)) return 1;
  static resim_recording_t rec;
  CHECK(record(&sc, &rec) == 0);
  size_t frames = rec.ndeltas + rec.nkeys;

  static resim_result_t res;
  CHECK(resim(&sc, &rec, &res) == 0);
  const resim_organ_result_t *r = &res.organs[0];
  printf("same scene: %llu frames, %llu exact, max error %.3g m\n", (unsigned long long)r->frames,
         (unsigned long long)r->exact, r->max_err);
  CHECK(r->frames == frames);
  CHECK(r->exact == r->frames);
  CHECK(r->max_err <= 0.5 * sc.quant_step + 5e-8);
  CHECK(res.steps == N);
  CHECK(res.sched[0].feedback_steps == RELEASE_AT && res.sched[0].releases == 1);

  /* A stiffer kidney dents less: frames in contact differ beyond the
   * quantization; frames before the contact still agree. */
  static scene_t stiff;
  stiff = sc;
  stiff.organs[0].material.stiffness *= 2;
  CHECK(resim(&stiff, &rec, &res) == 0);
  printf("stiffness x2: %llu exact of %llu, max error %.3g m\n", (unsigned long long)r->exact,
         (unsigned long long)r->frames, r->max_err);
  CHECK(r->max_err > 10 * sc.quant_step);
  CHECK(r->exact < r->frames && r->exact >= 2);

  /* Another scene name is refused before anything runs. */
  static scene_t other;
  other = sc;
  snprintf(other.name, sizeof other.name, "%s", "not-the-recorded-one");
  static runtime_t rt;
  CHECK(runtime_init(&rt, &other, &e) == 0);
  CHECK(resim_check_scene(&rt, &rec, &e) == -1);
  CHECK(strstr(e.msg, "scene mismatch") && strstr(e.msg, "kidney-palpation"));
  runtime_destroy(&rt);

  resim_recording_free(&rec);
  return check_report("test_resim_run");
}
