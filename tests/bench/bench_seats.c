/* SPDX-License-Identifier: Apache-2.0 */
/* bench_seats: what sharing a core costs a busy seat's physics step
 * (issue 17 item 6), without DDS or the scheduler in the way.
 *
 * A classroom puts several seats' servers on each core; each server sleeps
 * between its 1 ms ticks, so when its step starts the other seats' steps
 * have just run on that core and pushed its data out of the core's own
 * cache. This program loads SEATS copies of one scene (default
 * assets/scenes/classroom_gallbladder.yaml) into one process and drives
 * each with load_bench.sh --busy's trajectory (down 8 mm in 0.5 s at
 * x 12 mm, y 4 mm, then sweeping 5 mm either side every 2 s: the organ never
 * rests). Each simulated millisecond it steps every seat in turn on this one
 * thread and times each step (thread CPU time), so every seat's step finds
 * its data after the other seats' steps: the lab's cache, made repeatable.
 * With --seats 1 the seat's data stays in the cache from one step to the
 * next: the seat alone. Prints the median and p99 step time per seat count
 * and the ratio to one seat.
 *
 * --evict KB writes KB kB of other memory (a store per cache line, outside
 * the timed step) before every step: the step as it runs after other
 * processes had the core (a lab's seat: docs/numerics.md §11.3). 0, the
 * default, leaves the caches alone.
 *
 * --neighbour KB runs a second thread that writes KB kB of its own memory
 * over and over (a store per cache line) for as long as the seats step, on
 * CPU --neighbour-cpu N (default: wherever the scheduler puts it): what a
 * busy neighbour core costs a seat's step through what the cores share
 * (the last-level cache, the memory bus), with nothing taking the seat's
 * own core from it. Pin the bench itself elsewhere (taskset). A size that
 * fits the neighbour's own L2 stays off the shared parts; a larger one
 * does not (docs/numerics.md §11.5).
 *
 * --tick sleeps to the next 1 ms tick before each round of seats, as a
 * server's loop does (each round then starts from a wake-up; with several
 * seats the round steps them one after the other, as a seat group's
 * thread does: server/session/seat_group.h). Without it the rounds run
 * back to back.
 *
 * usage: bench_seats [--scene FILE] [--seats LIST] [--seconds S] [--evict KB] [--tick]
 *                    [--neighbour KB [--neighbour-cpu N]]
 *   defaults: classroom_gallbladder.yaml, seats 1,2,3, 4 s of simulated
 *   time each (the first 1 s, the press, is not timed).
 * Figures are not checked: the machine's load moves them; compare the
 * ratios of one run. */
#define _GNU_SOURCE /* pthread_setaffinity_np, CPU_SET */
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "busy_path.h"
#include "runtime/scene_runtime.h"
#include "test_assets.h"
#include "scene.h"
#include "vstats.h"
#include "vtime.h"

enum { MAX_SEATS = 8 };

/* Overwrites n bytes, one store per cache line: what other processes do to
 * the core's caches between two ticks of a server. */
static void evict(unsigned char *buf, size_t n, unsigned char v) {
  for (size_t i = 0; i < n; i += 64) buf[i] = v;
}

/* The busy neighbour: writes its buffer until told to stop. Owned by main;
 * the thread only reads buf, n, cpu and stop, and writes passes. */
typedef struct neighbour {
  unsigned char *buf;
  size_t n;
  int cpu; /* -1: not pinned */
  atomic_int stop;
  unsigned long passes;
  int pinned; /* the pin was refused: 0 */
} neighbour_t;

static void *neighbour_main(void *arg) {
  neighbour_t *nb = arg;
  if (nb->cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(nb->cpu, &set);
    nb->pinned = pthread_setaffinity_np(pthread_self(), sizeof set, &set) == 0;
  }
  unsigned char v = 1;
  while (!atomic_load_explicit(&nb->stop, memory_order_relaxed)) {
    evict(nb->buf, nb->n, v++);
    nb->passes++;
  }
  return NULL;
}

static int run(const scene_t *scene, int nseats, double seconds, unsigned char *junk, size_t njunk, int tick,
               vstats_summary_t *out) {
  static runtime_t rt[MAX_SEATS];
  verr_t err;
  for (int k = 0; k < nseats; k++)
    if (runtime_init(&rt[k], scene, &err)) {
      fprintf(stderr, "bench_seats: %s\n", err.msg);
      for (int j = 0; j < k; j++) runtime_destroy(&rt[j]);
      return -1;
    }
  const scene_t *sc = scene;
  const int steps = (int)lround(seconds / sc->dt), warm = (int)lround(1.0 / sc->dt);
  double *c = malloc((size_t)(steps - warm) * (size_t)nseats * sizeof *c);
  if (!c) return -1;
  size_t nc = 0;
  uint64_t next = vtime_mono_ns();
  for (int s = 0; s < steps; s++) {
    if (tick) {
      next += 1000000;
      vtime_sleep_until(next);
    }
    double p[3];
    busy_target(s * sc->dt, p);
    for (int k = 0; k < nseats; k++) {
      if (njunk) evict(junk, njunk, (unsigned char)(s + k));
      uint64_t c0 = vtime_thread_cpu_ns();
      runtime_set_tool(&rt[k], 0, p, 100);
      runtime_step(&rt[k]);
      uint64_t c1 = vtime_thread_cpu_ns();
      if (s >= warm) c[nc++] = (double)(c1 - c0) * 1e-3;
    }
  }
  *out = vstats_summarise(c, nc);
  free(c);
  for (int k = 0; k < nseats; k++) runtime_destroy(&rt[k]);
  return 0;
}

int main(int argc, char **argv) {
  const char *scene = NULL, *list = "1,2,3";
  double seconds = 4.0;
  long evict_kb = 0, neighbour_kb = 0, neighbour_cpu = -1;
  int tick = 0;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--scene") && i + 1 < argc)
      scene = argv[++i];
    else if (!strcmp(argv[i], "--seats") && i + 1 < argc)
      list = argv[++i];
    else if (!strcmp(argv[i], "--seconds") && i + 1 < argc)
      seconds = atof(argv[++i]);
    else if (!strcmp(argv[i], "--evict") && i + 1 < argc) {
      char *end;
      evict_kb = strtol(argv[++i], &end, 10);
      if (*end || end == argv[i]) evict_kb = -1;
    } else if ((!strcmp(argv[i], "--neighbour") || !strcmp(argv[i], "--neighbour-cpu")) && i + 1 < argc) {
      long *dst = argv[i][11] ? &neighbour_cpu : &neighbour_kb;
      char *end;
      *dst = strtol(argv[++i], &end, 10);
      if (*end || end == argv[i] || *dst < 0) *dst = -2;
    } else if (!strcmp(argv[i], "--tick"))
      tick = 1;
    else {
      fprintf(stderr, "usage: bench_seats [--scene FILE] [--seats LIST] [--seconds S] [--evict KB] [--tick] "
                      "[--neighbour KB [--neighbour-cpu N]]\n");
      return 2;
    }
  }
  if (!(seconds > 1.5 && seconds <= 600)) {
    fprintf(stderr, "bench_seats: --seconds must be in (1.5, 600]\n");
    return 2;
  }
  if (evict_kb < 0 || evict_kb > 1L << 20) {
    fprintf(stderr, "bench_seats: --evict takes 0..1048576 (kB)\n");
    return 2;
  }
  if (neighbour_kb < 0 || neighbour_kb > 1L << 20 || neighbour_cpu < -1 || neighbour_cpu >= CPU_SETSIZE) {
    fprintf(stderr, "bench_seats: --neighbour takes 0..1048576 (kB), --neighbour-cpu a CPU number\n");
    return 2;
  }
  size_t njunk = (size_t)evict_kb * 1024;
  unsigned char *junk = njunk ? calloc(njunk, 1) : NULL;
  if (njunk && !junk) return 1;
  if (!scene) scene = test_asset("scenes/classroom_gallbladder.yaml");
  static scene_t sc;
  verr_t err;
  if (scene_load(scene, &sc, &err)) { /* meshes relative to the scene file, as the server reads it */
    fprintf(stderr, "bench_seats: %s\n", err.msg);
    return 2;
  }
  printf("bench_seats: %s, busy trajectory, %.1f s simulated per run (first 1 s not timed)", scene, seconds);
  if (evict_kb) printf(", %ld kB of other data written before each step", evict_kb);
  if (tick) printf(", each round of seats after a sleep to the next 1 ms tick");
  neighbour_t nb = {.n = (size_t)neighbour_kb * 1024, .cpu = (int)neighbour_cpu};
  pthread_t nbt;
  if (nb.n) {
    nb.buf = calloc(nb.n, 1);
    if (!nb.buf || pthread_create(&nbt, NULL, neighbour_main, &nb)) {
      fprintf(stderr, "bench_seats: cannot start the neighbour\n");
      return 1;
    }
    printf(", a neighbour thread writing %ld kB over and over", neighbour_kb);
    if (neighbour_cpu >= 0) printf(" on CPU %ld", neighbour_cpu);
  }
  printf("\n");
  printf("%-6s %14s %14s %12s\n", "seats", "CPU median us", "CPU p99 us", "vs 1 seat");
  double base = NAN;
  const char *q = list;
  while (*q) {
    char *end;
    long n = strtol(q, &end, 10);
    if (end == q || n < 1 || n > MAX_SEATS) {
      fprintf(stderr, "bench_seats: --seats takes numbers 1..%d separated by commas\n", MAX_SEATS);
      return 2;
    }
    vstats_summary_t r;
    if (run(&sc, (int)n, seconds, junk, njunk, tick, &r)) return 1;
    if (n == 1) base = r.median;
    printf("%-6ld %14.1f %14.1f %11.2fx\n", n, r.median, r.p99, r.median / base);
    fflush(stdout);
    q = *end == ',' ? end + 1 : end;
  }
  if (nb.n) {
    atomic_store(&nb.stop, 1);
    pthread_join(nbt, NULL);
    printf("neighbour: %lu passes over %ld kB%s\n", nb.passes, neighbour_kb,
           nb.cpu >= 0 && !nb.pinned ? " (its CPU pin was refused: it ran where the scheduler put it)" : "");
    free(nb.buf);
  }
  free(junk);
  return 0;
}
