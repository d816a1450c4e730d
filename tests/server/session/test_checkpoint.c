/* SPDX-License-Identifier: Apache-2.0 */
/* test_checkpoint: a pressed organ saved and restored into a fresh runtime
 * continues exactly where it was; damaged, truncated, foreign and
 * mismatched files are refused and change nothing. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "test_runtime.h"
#include "session/checkpoint.h"

static int make(runtime_t *rt, const char *src, const char *name, const char *mesh) {
  (void)src; /* the support library finds the assets */
  static scene_t sc;
  return test_runtime_one_organ(rt, &sc, name, mesh, "", "stiffness: 400", NULL) ? 0 : -1;
}

/* Presses the probe 6 mm into the top of the organ for `steps` steps. */
static void press(runtime_t *rt, int steps) {
  const model_t *m = rt->organs[0].model;
  size_t top = 0;
  for (size_t i = 0; i < m->nsurf; i++)
    if (m->surf_x[3 * i + 2] > m->surf_x[3 * top + 2]) top = i;
  for (int s = 0; s < steps; s++) {
    double p[3] = {m->surf_x[3 * top], m->surf_x[3 * top + 1], 0};
    p[2] = rt->organs[0].rest.pos[3 * top + 2] + 0.01 - fmin(1.0, s / 100.0) * 0.016;
    runtime_set_tool(rt, 0, p, 4);
    runtime_step(rt);
  }
}

static double max_diff(const model_t *a, const model_t *b) {
  double d = 0;
  for (size_t i = 0; i < 3 * a->nnodes; i++) d = fmax(d, fabs(a->x[i] - b->x[i]));
  return d;
}

int main(void) {
  const char *src = getenv("VISCERA_SOURCE_DIR");
  CHECK(src != NULL);
  if (!src) return check_report("test_checkpoint");
  char path[200], bad[256];
  snprintf(path, sizeof path, "/tmp/viscera_test_ckpt_%d.bin", (int)getpid());
  snprintf(bad, sizeof bad, "%s.bad", path);
  static runtime_t a, b, c;
  session_tool_t ta[SCENE_MAX_TOOLS], tb[SCENE_MAX_TOOLS]; /* the session's tool records */
  memset(ta, 0, sizeof ta);
  memset(tb, 0, sizeof tb);
  CHECK(make(&a, src, "ck", "spleen.obj") == 0);
  CHECK(make(&b, src, "ck", "spleen.obj") == 0);
  thr_init(&ta[0].thr, 0.5, 0.8, 1.5);
  thr_init(&tb[0].thr, 0.5, 0.8, 1.5);
  press(&a, 200);
  ta[0].thr.time_above[THR_ST] = 0.25;
  ta[0].thr.path_length = 0.03;
  verr_t err;
  unlink(path);
  CHECK(checkpoint_load(path, &b, tb, NULL, &err) == 0); /* no file: fresh start */
  CHECK(checkpoint_save(path, &a, ta, NULL, &err) == 0);

  /* Damaged copies first: each refused, b untouched (still at rest). */
  FILE *f = fopen(path, "rb");
  static unsigned char bytes[1 << 20];
  size_t n = f ? fread(bytes, 1, sizeof bytes, f) : 0;
  if (f) fclose(f);
  CHECK(n > 1000);
  const struct {
    size_t len;
    long flip; /* byte to corrupt, -1: none */
    const char *expect;
  } cases[] = {{n / 2, -1, "damaged"},
               {n, (long)n / 3, "damaged"},
               {n, 0, "not a viscera checkpoint"},
               {7, -1, "not a viscera"}};
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    FILE *g = fopen(bad, "wb");
    if (!g) continue;
    unsigned char save = cases[k].flip >= 0 ? bytes[cases[k].flip] : 0;
    if (cases[k].flip >= 0) bytes[cases[k].flip] ^= 0x5a;
    fwrite(bytes, 1, cases[k].len, g);
    fclose(g);
    if (cases[k].flip >= 0) bytes[cases[k].flip] = save;
    CHECK(checkpoint_load(bad, &b, tb, NULL, &err) == -1);
    CHECK(strstr(err.msg, cases[k].expect) != NULL);
    CHECK(b.sim_time == 0 && b.steps == 0);
    CHECK(max_diff(a.organs[0].model, b.organs[0].model) > 1e-3); /* still at rest, a is pressed */
  }
  /* Another scene (name) and another organ (node count): refused. */
  CHECK(make(&c, src, "other", "spleen.obj") == 0);
  CHECK(checkpoint_load(path, &c, tb, NULL, &err) == -1 && strstr(err.msg, "another scene"));
  runtime_destroy(&c);
  CHECK(make(&c, src, "ck", "kidney.obj") == 0);
  CHECK(checkpoint_load(path, &c, tb, NULL, &err) == -1 && strstr(err.msg, "node count"));
  runtime_destroy(&c);

  /* The real one: restored exactly, and both continue identically. */
  CHECK(checkpoint_load(path, &b, tb, NULL, &err) == 1);
  CHECK(b.sim_time == a.sim_time && b.steps == a.steps);
  CHECK(max_diff(a.organs[0].model, b.organs[0].model) == 0);
  CHECK(tb[0].thr.time_above[THR_ST] == 0.25 && tb[0].thr.path_length == 0.03);
  CHECK(tb[0].thr.level[THR_MPF] == 0.8); /* levels stay the scene's */
  for (int s = 0; s < 50; s++) {          /* tool released in both: the dent relaxes the same way */
    runtime_release_tool(&a, 0);
    runtime_release_tool(&b, 0);
    runtime_step(&a);
    runtime_step(&b);
  }
  CHECK(max_diff(a.organs[0].model, b.organs[0].model) == 0);

  /* Background writer: the last submitted state is on disk after stop. */
  checkpointer_t *w = checkpointer_start(path, &err);
  CHECK(w != NULL);
  if (w) {
    for (int s = 0; s < 20; s++) {
      runtime_step(&a);
      checkpointer_submit(w, &a, ta, NULL);
    }
    uint64_t written = 0;
    CHECK(checkpointer_stop(w, &written, &err) == 0);
    CHECK(written >= 1);
    CHECK(checkpoint_load(path, &b, tb, NULL, &err) == 1);
    CHECK(b.steps == a.steps);
    CHECK(max_diff(a.organs[0].model, b.organs[0].model) == 0);
  }
  unlink(path);
  unlink(bad);
  runtime_destroy(&a);
  runtime_destroy(&b);
  return check_report("test_checkpoint");
}
