/* SPDX-License-Identifier: Apache-2.0 */
/* bench_topology: what a topology change costs the server end to end, on the
 * adaptive kidney (assets/scenes/kidney_adaptive.yaml): a scripted probe
 * presses in until the mesh refines, then lifts off until it simplifies,
 * `cycles` times. Per change it times
 *   model   the model's own refinement or simplification (adaptive core),
 *   follow  the runtime's rebuild: collision tree, surface view, proxy
 *           re-attachment (topology_follow.c),
 *   publish mesh_publisher_retopo: buffers, keyframe encode and dds_write of
 *           the new MeshState (with a DataReader of it in this process, so
 *           the write serializes and delivers),
 *   step    the whole runtime_step that changed (model step + change + follow),
 * and prints the keyframe size, against the median step without a change.
 * DDS is used only when CYCLONEDDS_URI is set (the loopback configuration);
 * otherwise publish is encode-only. Figures, never asserted.
 * usage: bench_topology ASSETS_DIR [--quick] [--domain N] */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "dds/vdds.h"
#include "physics/adaptive.h"
#include "runtime/scene_runtime.h"
#include "session/mesh_publisher.h"
#include "test_assets.h"
#include "test_runtime.h"
#include "vstats.h"
#include "vtime.h"

enum { MAX_CHANGES = 256 };

typedef struct series {
  double model[MAX_CHANGES], follow[MAX_CHANGES], publish[MAX_CHANGES], step[MAX_CHANGES];
  size_t n, bytes;
  size_t nverts;
} series_t;

static void row(const char *what, series_t *s) {
  if (!s->n) return;
  vstats_summary_t m = vstats_summarise(s->model, s->n), f = vstats_summarise(s->follow, s->n),
                   p = vstats_summarise(s->publish, s->n), st = vstats_summarise(s->step, s->n);
  printf("%-10s %4zu %7zu %9.0f %9.0f %9.0f %9.0f %9.0f %9.0f %9.0f %9.0f %10zu\n", what, s->n, s->nverts, m.median,
         m.max, f.median, f.max, p.median, p.max, st.median, st.max, s->bytes);
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: bench_topology ASSETS_DIR [--quick] [--domain N]\n");
    return 2;
  }
  int cycles = 20, domain = 84;
  for (int i = 2; i < argc; i++) {
    if (!strcmp(argv[i], "--quick")) cycles = 3;
    if (!strcmp(argv[i], "--domain") && i + 1 < argc) domain = cli_parse_domain(argv[++i]);
  }
  static scene_t sc;
  static runtime_t rt;
  verr_t err;
  test_assets_dir_set(argv[1]);
  if (!test_runtime_load_scene(&rt, &sc, "kidney_adaptive.yaml", &err)) {
    fprintf(stderr, "bench_topology: %s\n", err.msg);
    return 1;
  }
  organ_rt_t *o = &rt.organs[0];
  model_t *m = o->model;
  adaptive_model_t *am = model_adaptive_of(m);
  vdds_t dds;
  memset(&dds, 0, sizeof dds);
  dds_entity_t w_state = 0, r_state = 0;
  int use_dds = getenv("CYCLONEDDS_URI") != NULL && domain >= 0;
  if (use_dds) {
    if (vdds_open(&dds, domain, "bench/topology", &err) || (w_state = vdds_writer(&dds, VT_MESH_STATE, &err)) < 0 ||
        (r_state = vdds_reader(&dds, VT_MESH_STATE, &err)) < 0) {
      fprintf(stderr, "bench_topology: DDS: %s\n", err.msg);
      return 1;
    }
  }
  mesh_publisher_t mp;
  if (mesh_publisher_init(&mp, 0, m->nsurf, m->surf_tris, m->nsurf_tris, (float)sc.quant_step, w_state, 0, &err)) {
    fprintf(stderr, "bench_topology: %s\n", err.msg);
    return 1;
  }
  mesh_publisher_keyframe(&mp, m->surf_x, 0);
  static double plain[200000];
  size_t nplain = 0;
  series_t refine = {0}, simplify = {0};
  double dev[3] = {0.012, 0.004, 0.036};
  for (int c = 0; c < cycles; c++) {
    for (int phase = 0; phase < 2; phase++) { /* 0: press until refined, 1: lift until simplified */
      uint32_t v0 = o->topology_version;
      for (int s = 0; s < 20000 && o->topology_version == v0; s++) {
        dev[2] += phase == 0 ? -2e-5 : 1e-4;
        if (phase == 1 && dev[2] > 0.045) dev[2] = 0.045;
        runtime_set_tool(&rt, 0, dev, 4.0);
        double before_refine = am->ad.last_refine_us, before_simplify = am->ad.last_simplify_us;
        uint64_t t0 = vtime_mono_ns();
        runtime_step(&rt);
        double step_us = (double)(vtime_mono_ns() - t0) * 1e-3;
        if (o->topology_version == v0) {
          if (nplain < sizeof plain / sizeof plain[0]) plain[nplain++] = step_us;
          continue;
        }
        uint64_t p0 = vtime_mono_ns();
        mesh_publisher_retopo(&mp, o->topology_version, m->nsurf, m->surf_tris, m->nsurf_tris, m->surf_x, 0, &err);
        double pub_us = (double)(vtime_mono_ns() - p0) * 1e-3;
        series_t *sr = m->nsurf > am->ad.n0 ? &refine : &simplify;
        if (sr->n < MAX_CHANGES) {
          /* A re-centre is a simplification and a refinement in one step. */
          sr->model[sr->n] = (am->ad.last_refine_us != before_refine ? am->ad.last_refine_us : 0) +
                             (am->ad.last_simplify_us != before_simplify ? am->ad.last_simplify_us : 0);
          sr->follow[sr->n] = o->last_follow_us;
          sr->publish[sr->n] = pub_us;
          sr->step[sr->n] = step_us;
          sr->n++;
        }
        sr->bytes = mesh_publisher_keyframe_bytes(&mp);
        sr->nverts = m->nsurf;
      }
      if (use_dds) { /* drain the reader so its history does not grow the measurement */
        void *samples[1] = {0};
        dds_sample_info_t info;
        while (dds_take(r_state, samples, &info, 1, 1) > 0) dds_return_loan(r_state, samples, 1);
      }
    }
  }
  vstats_summary_t ps = vstats_summarise(plain, nplain);
  printf("bench_topology: kidney_adaptive (%zu coarse vertices), %d press/lift cycles, publish %s\n", am->ad.n0, cycles,
         use_dds ? "with dds_write (loopback, local reader)" : "encode only (CYCLONEDDS_URI not set)");
  printf("steps without a change: median %.0f us, p99 %.0f us (%zu steps)\n", ps.median, ps.p99, nplain);
  printf("%-10s %4s %7s %9s %9s %9s %9s %9s %9s %9s %9s %10s\n", "change", "n", "verts", "model_med", "model_max",
         "follow_med", "follow_max", "pub_med", "pub_max", "step_med", "step_max", "key_bytes");
  row("refine", &refine);
  row("simplify", &simplify);
  mesh_publisher_destroy(&mp);
  runtime_destroy(&rt);
  if (use_dds) vdds_close(&dds);
  return 0;
}
