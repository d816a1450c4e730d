/* SPDX-License-Identifier: Apache-2.0 */
/* bench_bullet: the surface mass-spring step against a Bullet soft body at
 * the same dent (issue 17 item 4, docs/numerics.md §8).
 *
 * For each organ (kidney, gallbladder; --quick: kidney, fewer steps):
 * viscera: the default material's mass_spring_surface scene with one probe
 * (400 N/m, the bench_server setting) through the product's runtime; the
 * probe comes down over the organ's highest vertex until it holds 1 N, is
 * held 0.5 s (the organ comes to rest, stab_settle), then `steps` steps are
 * timed one by one (median and p99 of the wall time per 1 ms step, and
 * the median of the thread's CPU time per step, which a busy machine
 * inflates less).
 * Bullet: a btSoftBody from the same rest surface (bullet_soft.h: links on
 * the edges, pose matching, 2 iterations, damping 0.05, same mass and
 * gravity), the probe's contact patch pinned where viscera holds it (the
 * same dent by construction), settled 0.5 s, then timed the same way,
 * the two sides in turns of 50 steps.
 * Prints one row per organ with both medians, their ratio (viscera /
 * Bullet) and the dent; the machine's load average is printed with them
 * (figures on a loaded machine are noisy: compare ratios). Figures are
 * never asserted.
 * usage: bench_bullet [--quick] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bullet_soft.h"
#include "runtime/scene_runtime.h"
#include "test_runtime.h"
#include "vmath.h"
#include "vstats.h"
#include "vtime.h"

static double load_average(void) {
  double l = NAN;
  FILE *f = fopen("/proc/loadavg", "r");
  if (f) {
    if (fscanf(f, "%lf", &l) != 1) l = NAN;
    fclose(f);
  }
  return l;
}

typedef struct side {
  vstats_summary_t t, cpu; /* wall and thread CPU us per step */
  double dent, speed;
} side_t;

static int run_organ(const char *organ, int steps) {
  static scene_t sc;
  static runtime_t rt;
  char mesh[64];
  snprintf(mesh, sizeof mesh, "%s.obj", organ);
  if (!test_runtime_one_organ(&rt, &sc, "bullet", mesh,
                              "    integrator: symplectic_euler\n    material: {mass: 0.15}\n",
                              "radius: 0.003, stiffness: 400, max_force: 4", NULL))
    return -1;
  model_t *m = rt.organs[0].model;
  size_t top = 0;
  for (size_t i = 1; i < m->nsurf; i++)
    if (m->surf_rest[3 * i + 2] > m->surf_rest[3 * top + 2]) top = i;
  double p[3];
  v3_copy(p, m->surf_rest + 3 * top);
  p[2] += 0.002;
  /* Down at 5 cm/s until 1 N, then held 0.5 s. */
  for (int s = 0; s < 2000 && v3_norm(rt.tools[0].force) < 1.0; s++) {
    p[2] -= 5e-5;
    runtime_set_tool(&rt, 0, p, 100);
    runtime_step(&rt);
  }
  for (int s = 0; s < 500; s++) {
    runtime_set_tool(&rt, 0, p, 100);
    runtime_step(&rt);
  }
  bullet_soft_t *b = bullet_soft_create(m->surf_rest, m->nsurf, m->surf_tris, m->nsurf_tris, 0.15, sc.gravity, 2, 0.05);
  double *t = malloc(4 * (size_t)steps * sizeof *t), *tb = t ? t + steps : NULL;
  double *c = t ? t + 2 * steps : NULL, *cb = t ? t + 3 * steps : NULL;
  if (!b || !t) {
    bullet_soft_destroy(b);
    free(t);
    runtime_destroy(&rt);
    return -1;
  }
  for (size_t j = 0; j < rt.tools[0].npatch; j++)
    bullet_soft_pin(b, rt.tools[0].patch[j], m->surf_x + 3 * (size_t)rt.tools[0].patch[j]);
  for (int s = 0; s < 500; s++) bullet_soft_step(b, sc.dt);
  /* Interleaved in blocks of 50 steps (each side keeps its caches warm
   * within a block): a change of the machine's load hits both sides
   * alike, so the ratio of the medians holds. */
  side_t vis = {0}, bul = {0};
  for (int s0 = 0; s0 < steps; s0 += 50) {
    int s1 = s0 + 50 < steps ? s0 + 50 : steps;
    for (int s = s0; s < s1; s++) {
      uint64_t t0 = vtime_mono_ns(), c0 = vtime_thread_cpu_ns();
      runtime_set_tool(&rt, 0, p, 100);
      runtime_step(&rt);
      c[s] = (double)(vtime_thread_cpu_ns() - c0) * 1e-3;
      t[s] = (double)(vtime_mono_ns() - t0) * 1e-3;
    }
    for (int s = s0; s < s1; s++) {
      uint64_t t0 = vtime_mono_ns(), c0 = vtime_thread_cpu_ns();
      bullet_soft_step(b, sc.dt);
      cb[s] = (double)(vtime_thread_cpu_ns() - c0) * 1e-3;
      tb[s] = (double)(vtime_mono_ns() - t0) * 1e-3;
    }
  }
  vis.t = vstats_summarise(t, (size_t)steps);
  vis.cpu = vstats_summarise(c, (size_t)steps);
  vis.dent = v3_dist(m->surf_x + 3 * top, m->surf_rest + 3 * top);
  for (size_t i = 0; i < 3 * m->nsurf; i++) vis.speed = fmax(vis.speed, fabs(m->v[i]));
  double force = v3_norm(rt.tools[0].force);
  bul.t = vstats_summarise(tb, (size_t)steps);
  bul.cpu = vstats_summarise(cb, (size_t)steps);
  double q[3];
  bullet_soft_node(b, (uint32_t)top, q);
  bul.dent = v3_dist(q, m->surf_rest + 3 * top);
  bul.speed = bullet_soft_max_speed(b);
  printf("%-12s %6zu %4d %9.1f %9.1f %9.1f %9.1f %7.2f %8.1f %8.1f %7.2f %8.3f %8.3f %7.3f %9.1e %9.1e %5.2f\n", organ,
         m->nsurf, m->substeps, vis.t.median, vis.t.p99, bul.t.median, bul.t.p99, vis.t.median / bul.t.median,
         vis.cpu.median, bul.cpu.median, vis.cpu.median / bul.cpu.median, vis.dent * 1e3, bul.dent * 1e3, force,
         vis.speed, bul.speed, load_average());
  bullet_soft_destroy(b);
  free(t);
  runtime_destroy(&rt);
  return 0;
}

int main(int argc, char **argv) {
  int quick = argc > 1 && !strcmp(argv[1], "--quick");
  printf("viscera mass_spring_surface (symplectic Euler, 1 ms steps) against Bullet %d-byte btSoftBody "
         "(2 iterations, damping 0.05), same dent; wall us per 1 ms step (median, p99), thread CPU us (median)\n",
         bullet_soft_scalar_bytes());
  printf("%-12s %6s %4s %9s %9s %9s %9s %7s %8s %8s %7s %8s %8s %7s %9s %9s %5s\n", "organ", "verts", "sub", "vis_med",
         "vis_p99", "bul_med", "bul_p99", "vis/bul", "vis_cpu", "bul_cpu", "cpu_v/b", "dent_mm", "bul_mm", "force_N",
         "vis_v", "bul_v", "load");
  static const char *organs[] = {"kidney", "gallbladder"};
  int rc = 0;
  for (int k = 0; k < (quick ? 1 : 2); k++) rc |= run_organ(organs[k], quick ? 50 : 2000);
  return rc ? 1 : 0;
}
