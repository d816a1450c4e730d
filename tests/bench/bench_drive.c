/* SPDX-License-Identifier: Apache-2.0 */
/* bench_drive: how the way a busy seat's probe is driven changes the
 * physics work of its step (issue 17 item 6; docs/numerics.md §11.8),
 * without DDS, clocks or other processes in the way.
 *
 * One copy of a scene (default assets/scenes/classroom_gallbladder.yaml)
 * is driven along load_bench.sh --busy's path (busy_path.h), one command
 * per simulated millisecond, as a server applies a trainee's commands:
 *   --holds P   each step after the first second, with chance P (seeded by
 *               --seed N), gets no new command: the probe stands still for
 *               a step and catches up at the next (what a server does when
 *               a command arrives just after the step that should have
 *               taken it);
 *   --join S    the server first hears the path S s into it (earlier
 *               commands lost: a client's writer not yet matched by the
 *               server's reader), so the probe appears where the path is
 *               then (inside the organ for S >= 0.41 s).
 * Prints the physics work (node updates of regional sleeping per step,
 * server/runtime/region_work.h) per 2 s of simulated time and its mean:
 * the figure a lab seat's server gives in its summary. Deterministic: the
 * same options give the same figures on any machine.
 *
 * usage: bench_drive [--scene FILE] [--seconds S] [--holds P] [--seed N] [--join S]
 *   defaults: classroom_gallbladder.yaml, 20 s, no holds, seed 1, join 0 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "busy_path.h"
#include "runtime/region_work.h"
#include "runtime/scene_runtime.h"
#include "scene.h"
#include "test_assets.h"
#include "test_rng.h"

int main(int argc, char **argv) {
  const char *scene = NULL;
  double seconds = 20, holds = 0, join = 0;
  unsigned long seed = 1;
  for (int i = 1; i < argc; i++) {
    char *end = NULL;
    if (!strcmp(argv[i], "--scene") && i + 1 < argc)
      scene = argv[++i];
    else if (!strcmp(argv[i], "--seconds") && i + 1 < argc)
      seconds = strtod(argv[++i], &end);
    else if (!strcmp(argv[i], "--holds") && i + 1 < argc)
      holds = strtod(argv[++i], &end);
    else if (!strcmp(argv[i], "--join") && i + 1 < argc)
      join = strtod(argv[++i], &end);
    else if (!strcmp(argv[i], "--seed") && i + 1 < argc)
      seed = strtoul(argv[++i], &end, 10);
    else {
      fprintf(stderr, "usage: bench_drive [--scene FILE] [--seconds S] [--holds P] [--seed N] [--join S]\n");
      return 2;
    }
    if (end && *end) {
      fprintf(stderr, "bench_drive: %s '%s' is not a number\n", argv[i - 1], argv[i]);
      return 2;
    }
  }
  if (!(seconds >= 2 && seconds <= 600) || !(holds >= 0 && holds <= 0.5) || !(join >= 0 && join <= 60)) {
    fprintf(stderr, "bench_drive: --seconds 2..600, --holds 0..0.5, --join 0..60\n");
    return 2;
  }
  if (!scene) scene = test_asset("scenes/classroom_gallbladder.yaml");
  static scene_t sc;
  static runtime_t rt;
  verr_t err;
  if (scene_load(scene, &sc, &err) || runtime_init(&rt, &sc, &err)) {
    fprintf(stderr, "bench_drive: %s\n", err.msg);
    return 2;
  }
  uint64_t rng = seed;
  const long steps = lround(seconds / sc.dt), window = lround(2.0 / sc.dt), warm = lround(1.0 / sc.dt);
  printf("bench_drive: %s, busy path joined at %.3f s, holds %.4f (seed %lu), %.0f s simulated\n", scene, join, holds,
         seed, seconds);
  printf("node updates per step, each 2 s:");
  double p[3], was[3];
  busy_target(join, was);
  long nholds = 0;
  uint64_t last = 0;
  for (long s = 0; s < steps; s++) {
    busy_target(join + (double)s * sc.dt, p);
    if (s >= warm && test_rng_uniform(&rng) < holds) {
      nholds++;
      runtime_set_tool(&rt, 0, was, 100); /* no command this step: the tool holds */
    } else {
      runtime_set_tool(&rt, 0, p, 100);
      memcpy(was, p, sizeof was);
    }
    runtime_step(&rt);
    if ((s + 1) % window == 0) {
      region_work_t w = runtime_region_work(&rt);
      printf(" %.0f", (double)(w.node_updates - last) / (double)window);
      last = w.node_updates;
    }
  }
  region_work_t w = runtime_region_work(&rt);
  printf("\nbench_drive: mean %.1f node updates per step, %ld holds (%.2f %% of the steps after the first second)\n",
         (double)w.node_updates / (double)steps, nholds, 100.0 * (double)nholds / (double)(steps - warm));
  runtime_destroy(&rt);
  return w.organs ? 0 : 1;
}
