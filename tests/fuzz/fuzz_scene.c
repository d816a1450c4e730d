/* SPDX-License-Identifier: Apache-2.0 */
/* fuzz_scene: mutated scene files against the scene parser and, when a
 * mutant is accepted, the simulation runtime (fuzz_files.h; issue 15
 * items 3 and 5). Contracts: scene_load_string never crashes; a refusal
 * names the file and line ("fuzz.yaml:N: ..."); an accepted scene has
 * every numeric value inside its range (scene_limits.h); an accepted scene
 * whose organs use the small meshes builds or is refused with a message,
 * and 20 steps of it leave every surface finite.
 * Corpus: the .yaml files of tests/fuzz/corpus/scene (meshes relative to assets/scenes). */
#include <math.h>

#include "fuzz_files.h"
#include "runtime/scene_runtime.h"
#include "scene.h"
#include "scene_limits.h"
#include "test_assets.h"

static const char *const dict[] = {"organs:\n",
                                   "tools:\n",
                                   "physics:\n",
                                   "material:\n",
                                   "  - name: x\n",
                                   "mass: ",
                                   "stiffness: ",
                                   "dt: ",
                                   "scale: ",
                                   "position: [",
                                   "]",
                                   "[",
                                   "{",
                                   "}",
                                   ": ",
                                   ", ",
                                   "\n",
                                   "\n    ",
                                   "  ",
                                   "- ",
                                   "~",
                                   "null",
                                   "\"q\"",
                                   "&a ",
                                   "*a",
                                   "0x10",
                                   "1_000",
                                   ".nan",
                                   ".inf",
                                   "-.inf",
                                   "1e999",
                                   "#",
                                   "---\n",
                                   "model: xpbd\n",
                                   "model: pbd\n",
                                   "kind: grasper\n",
                                   "thresholds: {st: 1, mpf: 2, sft: 3}\n",
                                   "fixed_below: ",
                                   "solver: {substeps: 256}\n",
                                   "mesh: ../meshes/spleen.obj\n",
                                   "mesh: /nonexistent.obj\n",
                                   "mesh: .\n",
                                   "\t",
                                   "\r\n",
                                   "\xc3\xa9"};

static runtime_t rt; /* large: static */
static scene_t sc;

static int in_range(const char *key, double v) { return scene_limit_ok(scene_limit(key), v); }

/* The accepted scene's values against the table; NULL or the first key out. */
static const char *ranges_hold(const scene_t *s) {
  if (!in_range("physics.dt", s->dt)) return "physics.dt";
  for (size_t i = 0; i < s->norgans; i++) {
    const scene_organ_t *o = &s->organs[i];
    if (!in_range("organs.scale", o->scale)) return "organs.scale";
    if (!in_range("organs.material.mass", o->material.mass)) return "organs.material.mass";
    if (!in_range("organs.material.stiffness", o->material.stiffness)) return "organs.material.stiffness";
    if (!in_range("organs.material.home_stiffness", o->material.home_stiffness)) return "home_stiffness";
    if (!in_range("organs.material.damping", o->material.damping)) return "organs.material.damping";
    for (int k = 0; k < 3; k++)
      if (!in_range("organs.position", o->position[k])) return "organs.position";
  }
  for (size_t t = 0; t < s->ntools; t++) {
    if (!in_range("tools.radius", s->tools[t].radius)) return "tools.radius";
    if (!in_range("tools.stiffness", s->tools[t].stiffness)) return "tools.stiffness";
    if (!in_range("tools.max_force", s->tools[t].max_force)) return "tools.max_force";
  }
  return NULL;
}

/* Only organs on the small meshes are built (a round stays milliseconds). */
static int small_meshes(const scene_t *s) {
  for (size_t i = 0; i < s->norgans; i++) {
    const char *m = strrchr(s->organs[i].mesh, '/');
    m = m ? m + 1 : s->organs[i].mesh;
    if (strcmp(m, "tissue_block.obj") && strcmp(m, "spleen.obj")) return 0;
  }
  return 1;
}

static const char *run_scene(const char *text, const char *base, long *built) {
  verr_t e;
  if (scene_load_string(text, "fuzz.yaml", base, &sc, &e)) {
    if (strncmp(e.msg, "fuzz.yaml:", 10)) return "a refusal does not name the file";
    return NULL;
  }
  const char *bad = ranges_hold(&sc);
  if (bad) return "an accepted scene holds a value out of its range";
  if (!small_meshes(&sc)) return NULL;
  if (runtime_init(&rt, &sc, &e)) return e.msg[0] ? NULL : "runtime refused without a message";
  (*built)++;
  for (int k = 0; k < 20; k++) runtime_step(&rt);
  const char *why = NULL;
  for (size_t i = 0; i < rt.norgans && !why; i++) {
    const model_t *m = rt.organs[i].model;
    for (size_t c = 0; c < 3 * m->nsurf; c++)
      if (!isfinite(m->surf_x[c])) {
        why = "a surface is not finite after 20 steps";
        break;
      }
  }
  runtime_destroy(&rt);
  return why;
}

int main(int argc, char **argv) {
  fuzz_run_t r = {0};
  if (fuzz_args(&r, "fuzz_scene", argc, argv)) return 2;
  fuzz_corpus_t c;
  if (fuzz_corpus_load(&c, r.corpus_dir, ".yaml")) {
    fprintf(stderr, "fuzz_scene: no .yaml seeds in %s\n", r.corpus_dir);
    return 1;
  }
  char base[1100];
  snprintf(base, sizeof base, "%s/assets/scenes", test_source_dir());
  int failed = 0;
  long built = 0, rounds = 0;
  double t0 = fuzz_now();
  fuzz_buf_t b = {0};
  /* Round -1..: each seed as it is first (the corpus must pass unmutated). */
  for (long i = -(long)c.n; i < r.iterations; i++, rounds++) {
    if (fuzz_now() - t0 > r.cap_s) {
      printf("fuzz_scene: safety stop after %ld rounds (%.0f s cap)\n", rounds, r.cap_s);
      break;
    }
    uint64_t s = r.seed * 0x9e3779b97f4a7c15ull + (uint64_t)i;
    size_t pick = i < 0 ? (size_t)(i + (long)c.n) : fuzz_below(&s, c.n);
    b.n = 0;
    if (fuzz_buf_reserve(&b, c.data[pick].n + 1)) return 1;
    memcpy(b.p, c.data[pick].p, c.data[pick].n + 1);
    b.n = c.data[pick].n;
    if (i >= 0) fuzz_mutate(&b, &s, dict, sizeof dict / sizeof *dict);
    fuzz_pending(&r, i, ".yaml", b.p, b.n);
    const char *why = run_scene((const char *)b.p, base, &built);
    if (why) {
      fuzz_failed(&r, i, why);
      failed++;
    } else {
      fuzz_passed(&r);
    }
  }
  printf("fuzz_scene: %ld rounds from %zu seeds, %ld scenes built and stepped, %d failed\n", rounds, c.n, built,
         failed);
  free(b.p);
  fuzz_corpus_free(&c);
  return failed ? 1 : 0;
}
