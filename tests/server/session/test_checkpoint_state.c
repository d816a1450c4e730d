/* SPDX-License-Identifier: Apache-2.0 */
/* test_checkpoint_state: checkpoints of everything a session changes
 * (checkpoint format 2, issue 7), on the real runtime:
 * - stones, tasks and tool tallies: a stone carried out (removed, its task
 *   completed) and one held half-way are restored with their positions,
 *   the held one dropped (grasps are not restored), the tasks' states and
 *   times, the tallies and measures exact;
 * - a cut xpbd spleen restored into a fresh runtime has the same nodes,
 *   tetrahedra, surface (triangles, positions, rest positions) bit for bit,
 *   and both then simulate AND cut again identically (the cutter's memory
 *   of the first cut restored too);
 * - a cut mass_spring_surface block likewise restores its nodes, springs'
 *   triangles, residual forces and sub-steps bit for bit and keeps
 *   simulating; a crafted triangle index is refused and the runtime rebuilt
 *   at rest;
 * - a refined adaptive kidney is restored bit for bit (the refinement
 *   redone at its centre) and runs on identically; a crafted centre is
 *   refused;
 * - tool roles (owner, guide, authority, coupling) restored, and a crafted
 *   role (authority out of range, a count unlike the scene's) refused;
 * - damaged, truncated, older-format and crafted files (a valid CRC around
 *   huge node, byte and cutter counts, out-of-range task and object
 *   states) are refused and leave the runtime at rest. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "test_runtime.h"
#include "physics/pbd.h"
#include "runtime/checkpoint_state.h"
#include "session/checkpoint.h"
#include "vtime.h"

static runtime_t a, b; /* large */
static scene_t sc;
static session_tool_t ta[SCENE_MAX_TOOLS], tb[SCENE_MAX_TOOLS]; /* the session's tool records */
static tool_roles_t ra, rb;
static char path[200], bad[240];
static verr_t err;

static int load(runtime_t *rt, const char *yaml) {
  if (!test_runtime_load(rt, &sc, yaml, &err)) return 0;
  session_tool_t *st = rt == &a ? ta : tb;
  for (size_t t = 0; t < rt->ntools; t++) thr_init(&st[t].thr, 0.5, 0.8, 1.5);
  for (size_t t = 0; t < SCENE_MAX_TOOLS; t++) memset(&st[t].tally, 0, sizeof st[t].tally);
  return 1;
}

/* Steps rt n times with tool t moving from p to q, buttons held; the
 * server's per-step bookkeeping (tallies, events drained) done as well. */
static void drive(runtime_t *rt, size_t t, const double p[3], const double q[3], int n, uint32_t buttons) {
  for (int i = 1; i <= n; i++) {
    double x[3];
    for (int k = 0; k < 3; k++) x[k] = p[k] + (q[k] - p[k]) * i / n;
    runtime_set_tool(rt, t, x, 4);
    runtime_set_buttons(rt, t, buttons);
    runtime_step(rt);
    for (size_t k = 0; k < rt->ntools; k++)
      tool_tally_update(rt == &a ? &ta[k].tally : &tb[k].tally, &rt->tools[k], rt->scene.dt);
    rt->events.n = 0;
  }
}

static size_t read_file(const char *p, unsigned char **out) {
  FILE *f = fopen(p, "rb");
  if (!f) return 0;
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  *out = malloc(n > 0 ? (size_t)n : 1);
  size_t got = *out ? fread(*out, 1, (size_t)n, f) : 0;
  fclose(f);
  return got;
}

static uint32_t crc32(const unsigned char *p, size_t n) {
  uint32_t c = 0xffffffffu;
  for (size_t i = 0; i < n; i++) {
    c ^= p[i];
    for (int k = 0; k < 8; k++) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return ~c;
}

/* Writes bytes[0..len) to `bad` with a correct CRC after them (reseal = 1:
 * the crafted content must pass the CRC and be refused on its merits). */
static void write_bad(const unsigned char *bytes, size_t len, int reseal) {
  FILE *g = fopen(bad, "wb");
  if (!g) return;
  fwrite(bytes, 1, len, g);
  if (reseal) {
    uint64_t crc = crc32(bytes, len);
    fwrite(&crc, 8, 1, g);
  }
  fclose(g);
}

#define KIDNEY_STONES                                                                                                  \
  "scene: t\norgans:\n  - {name: kidney, mesh: ../meshes/kidney.obj, material: {mass: 0.15}}\n"                        \
  "tools:\n  - {name: x, kind: extractor, radius: 0.0015, grasp_radius: 0.003, stiffness: 300}\n"                      \
  "objects:\n  - {name: s1, radius: 0.004, position: [-0.015, 0, 0.016], organ: kidney}\n"                             \
  "  - {name: s2, radius: 0.003, position: [0.012, 0, 0.016], organ: kidney}\n"                                        \
  "tasks:\n  - {name: out1, kind: stone_removal, tool: x, object: s1}\n"                                               \
  "  - {name: out2, kind: stone_removal, tool: x, object: s2}\n"

static void test_objects_tasks_tallies(void) {
  CHECK(load(&a, KIDNEY_STONES));
  /* s1 carried out (removed, out1 completed); s2 taken and held half-way. */
  double up1[3] = {-0.015, 0, 0.07}, at1[3] = {-0.015, 0, 0.021};
  drive(&a, 0, up1, at1, 400, 0);
  drive(&a, 0, at1, at1, 10, 1);
  drive(&a, 0, at1, up1, 1200, 1);
  drive(&a, 0, up1, up1, 10, 0);
  double up2[3] = {0.012, 0, 0.07}, at2[3] = {0.012, 0, 0.020}, mid2[3] = {0.012, 0, 0.026};
  drive(&a, 0, up1, up2, 100, 0);
  drive(&a, 0, up2, at2, 400, 0);
  drive(&a, 0, at2, at2, 10, 1);
  drive(&a, 0, at2, mid2, 200, 1);
  CHECK(a.stones[0].removed && a.tasks[0].completed && a.stones[0].held_by < 0);
  CHECK(!a.stones[1].removed && a.stones[1].held_by == 0 && a.tasks[1].started && !a.tasks[1].completed);
  CHECK(ta[0].tally.grasps == 2 && ta[0].tally.grasp_time > 1.0 && ta[0].tally.was_holding);
  ta[0].thr.time_above[THR_MPF] = 0.125; /* measures ride along as before */
  tool_roles_init(&ra, &sc);
  CHECK(tool_roles_restore(&ra, 0, "alice", "drsmith", 0.5, 150) == 0);
  CHECK(tool_roles_restore(&ra, 0, "alice", "alice", 0.5, 150) == -1); /* the owner cannot guide */
  CHECK(checkpoint_save(path, &a, ta, &ra, &err) == 0);

  CHECK(load(&b, KIDNEY_STONES));
  tool_roles_init(&rb, &sc);
  rb.changed = 0;
  CHECK(checkpoint_load(path, &b, tb, &rb, &err) == 1);
  CHECK(!strcmp(rb.tool[0].owner, "alice") && !strcmp(rb.tool[0].guide, "drsmith"));
  CHECK(rb.tool[0].authority == 0.5 && rb.tool[0].coupling == 150 && rb.tool[0].version == 2 && (rb.changed & 1u));
  CHECK(b.sim_time == a.sim_time && b.steps == a.steps);
  { /* the resume state's start time, read without restoring it (viscera-resim's span) */
    state_blob_t rs = {0};
    CHECK(checkpoint_resume_state(&rs, &a, ta, &err) == 0);
    double t0 = -1;
    CHECK(a.sim_time > 1 && ckpt_state_sim_time(rs.p, rs.len, &t0) == 0 && t0 == a.sim_time);
    CHECK(ckpt_state_sim_time(rs.p, SCENE_NAME_LEN + 7, &t0) == -1); /* header cut short */
    double nan_t = NAN;
    memcpy(rs.p + SCENE_NAME_LEN, &nan_t, sizeof nan_t);
    CHECK(ckpt_state_sim_time(rs.p, rs.len, &t0) == -1);
    free(rs.p);
  }
  for (size_t k = 0; k < 2; k++) {
    CHECK(memcmp(b.stones[k].pos, a.stones[k].pos, sizeof a.stones[k].pos) == 0);
    CHECK(b.stones[k].removed == a.stones[k].removed);
    CHECK(b.tasks[k].started == a.tasks[k].started && b.tasks[k].completed == a.tasks[k].completed);
    CHECK(b.tasks[k].t_start == a.tasks[k].t_start && (!a.tasks[k].completed || b.tasks[k].t_end == a.tasks[k].t_end));
  }
  CHECK(b.stones[1].held_by == -1); /* dropped where it was: the extractor re-enters */
  CHECK(tb[0].tally.grasps == ta[0].tally.grasps && tb[0].tally.grasp_time == ta[0].tally.grasp_time &&
        !tb[0].tally.was_holding);
  CHECK(tb[0].thr.time_above[THR_MPF] == 0.125);
  viscera_ToolMetrics ma, mb;
  tool_metrics_fill(&ma, &a, 0, &ta[0].thr, &ta[0].tally, 0);
  tool_metrics_fill(&mb, &b, 0, &tb[0].thr, &tb[0].tally, 0);
  CHECK(mb.tasks_total == 2 && mb.tasks_completed == 1 && mb.operation_time == ma.operation_time);
  CHECK(mb.grasps == ma.grasps && mb.grasp_time == ma.grasp_time);
  printf("objects: s1 removed at z %.4f, s2 held at z %.4f restored dropped; out1 %.3f s; %u grasps, %.3f s held\n",
         b.stones[0].pos[2], b.stones[1].pos[2], b.tasks[0].t_end - b.tasks[0].t_start, tb[0].tally.grasps,
         tb[0].tally.grasp_time);

  /* Crafted task and object states behind a valid CRC: refused, a fresh b
   * at rest and left so. */
  runtime_destroy(&b);
  CHECK(load(&b, KIDNEY_STONES));
  unsigned char *bytes = NULL;
  size_t n = read_file(path, &bytes);
  CHECK(n > 200);
  if (n > 200) {
    size_t body = n - 8;
    /* The roles close the body: their count, then per tool two 32-byte
     * names, authority, coupling. Before them the last stone's `removed`;
     * the stones (40 bytes each) follow their count, which follows the
     * tasks. */
    size_t roles_at = body - (8 + 80), authority_at = roles_at + 8 + 64;
    size_t removed_at = roles_at - 8, held_at = roles_at - 16, count_at = roles_at - 2 * 40 - 8;
    size_t task1_started = count_at - 32;
    struct {
      size_t at;
      uint64_t v;
      const char *why;
    } bad_fields[] = {{removed_at, 2, "bad object state"},
                      {held_at, 5, "bad object state"},
                      {count_at, 1u << 30, "object count"},
                      {task1_started, 7, "bad task state"},
                      {count_at - 2 * 32 - 8, 3, "task count"},
                      {roles_at, 3, "tool role count"},
                      {authority_at, 0x4000000000000000ull /* 2.0 */, "bad tool role"}};
    for (size_t k = 0; k < sizeof bad_fields / sizeof bad_fields[0]; k++) {
      uint64_t save;
      memcpy(&save, bytes + bad_fields[k].at, 8);
      memcpy(bytes + bad_fields[k].at, &bad_fields[k].v, 8);
      write_bad(bytes, body, 1);
      memcpy(bytes + bad_fields[k].at, &save, 8);
      CHECK(checkpoint_load(bad, &b, tb, &rb, &err) == -1); /* b stays at rest: no reload needed */
      if (!strstr(err.msg, bad_fields[k].why)) fprintf(stderr, "  case %zu: %s\n", k, err.msg);
      CHECK(strstr(err.msg, bad_fields[k].why) != NULL);
      CHECK(b.steps == 0 && !b.tasks[0].started && !b.stones[0].removed);
    }
  }
  free(bytes);
  runtime_destroy(&a);
  runtime_destroy(&b);
}

#define SPLEEN_XPBD                                                                                                    \
  "scene: t\norgans:\n  - name: spleen\n    mesh: ../meshes/spleen.obj\n    model: xpbd\n"                             \
  "    material: {mass: 0.15, distance_compliance: 2.0e-3, volume_compliance: 1.0e-4, home_stiffness: 30}\n"           \
  "    solver: {substeps: 1, iterations: 8, tet_size: 0.005}\n"                                                        \
  "tools:\n  - {name: knife, kind: scalpel, radius: 0.001, blade_length: 0.02}\n"

static int same_model(const model_t *p, const model_t *q) {
  if (p->nnodes != q->nnodes || p->ntets != q->ntets || p->nsurf != q->nsurf || p->nsurf_tris != q->nsurf_tris ||
      p->topology_version != q->topology_version)
    return 0;
  return !memcmp(p->x, q->x, 3 * p->nnodes * sizeof(double)) && !memcmp(p->v, q->v, 3 * p->nnodes * sizeof(double)) &&
         !memcmp(p->x_rest, q->x_rest, 3 * p->nnodes * sizeof(double)) &&
         !memcmp(p->surf_x, q->surf_x, 3 * p->nsurf * sizeof(double)) &&
         !memcmp(p->surf_rest, q->surf_rest, 3 * p->nsurf * sizeof(double)) &&
         !memcmp(p->surf_tris, q->surf_tris, 3 * p->nsurf_tris * sizeof(uint32_t));
}

/* A cut along y = const at height z, from x0 to x1, in and out. */
static void cut(runtime_t *rt, double y, double x0, double x1) {
  double above0[3] = {x0, y, 0.058}, in0[3] = {x0, y, 0.030}, in1[3] = {x1, y, 0.030}, above1[3] = {x1, y, 0.058};
  drive(rt, 0, above0, above0, 10, 0);
  drive(rt, 0, above0, in0, 100, 1);
  drive(rt, 0, in0, in1, 200, 1);
  drive(rt, 0, in1, above1, 100, 1);
  drive(rt, 0, above1, above1, 10, 0);
}

static void test_cut_xpbd(void) {
  CHECK(load(&a, SPLEEN_XPBD));
  size_t nv0 = a.organs[0].model->nsurf;
  cut(&a, 0, -0.02, 0.02);
  const model_t *ma = a.organs[0].model;
  CHECK(ma->topology_version > 0 && ma->nsurf > nv0);
  uint64_t t0 = vtime_mono_ns();
  CHECK(checkpoint_save(path, &a, ta, NULL, &err) == 0);
  double save_ms = (double)(vtime_mono_ns() - t0) * 1e-6;
  CHECK(load(&b, SPLEEN_XPBD));
  t0 = vtime_mono_ns();
  int r = checkpoint_load(path, &b, tb, NULL, &err);
  double load_ms = (double)(vtime_mono_ns() - t0) * 1e-6;
  if (r != 1) fprintf(stderr, "  %s\n", err.msg);
  CHECK(r == 1);
  const model_t *mb = b.organs[0].model;
  CHECK(same_model(ma, mb));
  CHECK(b.organs[0].topology_version == mb->topology_version); /* the runtime followed (tree, proxies) */
  CHECK(b.organs[0].tree.ntris == mb->nsurf_tris);
  /* What the physics loop pays per periodic checkpoint of the cut organ
   * (the copy; the writer thread does the disk). */
  checkpointer_t *w = checkpointer_start(bad, &err);
  double submit_us = 0, first_us = 0;
  CHECK(w != NULL);
  if (w) {
    for (int k = 0; k < 5; k++) {
      t0 = vtime_mono_ns();
      checkpointer_submit(w, &a, ta, NULL);
      double us = (double)(vtime_mono_ns() - t0) * 1e-3;
      if (k == 0)
        first_us = us; /* buffers grow */
      else
        submit_us = fmax(submit_us, us);
      vtime_sleep_until(vtime_mono_ns() + 20000000ull);
    }
    uint64_t written = 0;
    CHECK(checkpointer_stop(w, &written, &err) == 0 && written >= 1);
  }
  unsigned char *bytes = NULL;
  size_t n = read_file(path, &bytes);
  printf("periodic checkpoint of the cut spleen: submit (the copy in the physics loop) %.0f us the first time "
         "(buffers grow), then %.0f us max of 4\n",
         first_us, submit_us);
  printf("cut xpbd spleen: %zu -> %zu surface vertices, %zu nodes, %zu tetrahedra, topology %u; checkpoint %zu bytes, "
         "save %.1f ms, load %.1f ms (file system of /tmp, machine shared)\n",
         nv0, ma->nsurf, ma->nnodes, ma->ntets, ma->topology_version, n, save_ms, load_ms);
  /* Both go on alike: released tool, the tissue relaxes; then a second
   * cut across the first one changes both topologies the same way. */
  double park[3] = {0.02, 0, 0.058};
  drive(&a, 0, park, park, 100, 0);
  drive(&b, 0, park, park, 100, 0);
  CHECK(same_model(ma, mb));
  cut(&a, 0.01, -0.01, 0.01);
  cut(&b, 0.01, -0.01, 0.01);
  CHECK(same_model(ma, mb));
  printf("after a second cut in both: %zu surface vertices (original) vs %zu (restored), topology %u vs %u\n",
         ma->nsurf, mb->nsurf, ma->topology_version, mb->topology_version);

  /* Damaged and crafted copies: each refused, a fresh b at rest and left so
   * (untouched, or rebuilt from the scene when a topology restore failed). */
  runtime_destroy(&b);
  CHECK(load(&b, SPLEEN_XPBD));
  size_t ns0 = b.organs[0].model->nsurf;
  if (n > 1000) {
    size_t body = n - 8;
    uint64_t nn, blob_len;
    const size_t nn_at = 8 + SCENE_NAME_LEN + 8 + 8 + 8;
    memcpy(&nn, bytes + nn_at, 8);
    size_t blob_len_at = nn_at + 16 + 48 * nn;
    memcpy(&blob_len, bytes + blob_len_at, 8);
    size_t blob_at = blob_len_at + 8;
    struct {
      size_t at; /* u64 to overwrite, or SIZE_MAX: none */
      uint64_t v;
      size_t len; /* bytes written before the CRC */
      int reseal;
      const char *why;
    } cases[] = {
        {SIZE_MAX, 0, n / 2, 0, "damaged"},
        {SIZE_MAX, 0, n - 1, 0, "damaged"},
        {nn_at, 1ull << 60, body, 1, "beyond the file"},
        {nn_at, nn + 1, body, 1, ""},
        {blob_len_at, 1ull << 62, body, 1, "truncated topology data"},
        {blob_len_at, blob_len - 8, body, 1, ""},
        {blob_at, 1ull << 40, body, 1, "bad node or tetrahedron count"},
        {blob_at + 8, 1ull << 40, body, 1, "bad node or tetrahedron count"},
        {blob_at, nn - 1, body, 1, "topology"},
        {nn_at + 8, 0, body, 1, "node count differs"},
        {0, 0x313054504B435356ull, body, 1, "checkpoint format 01"}, /* "VSCKPT01" */
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
      uint64_t save = 0;
      if (cases[k].at != SIZE_MAX) {
        memcpy(&save, bytes + cases[k].at, 8);
        memcpy(bytes + cases[k].at, &cases[k].v, 8);
      }
      write_bad(bytes, cases[k].len, cases[k].reseal);
      if (cases[k].at != SIZE_MAX) memcpy(bytes + cases[k].at, &save, 8);
      CHECK(checkpoint_load(bad, &b, tb, NULL, &err) == -1);
      if (!strstr(err.msg, cases[k].why)) fprintf(stderr, "  case %zu: %s\n", k, err.msg);
      CHECK(strstr(err.msg, cases[k].why) != NULL && strstr(err.msg, "starting from rest") != NULL);
      const model_t *m = b.organs[0].model;
      CHECK(b.steps == 0 && m->topology_version == 0 && m->nsurf == ns0);
      CHECK(b.organs[0].topology_version == 0);
    }
  }
  free(bytes);
  runtime_destroy(&a);
  runtime_destroy(&b);
}

#define BLOCK_MS                                                                                                       \
  "scene: t\norgans:\n  - {name: block, mesh: ../meshes/tissue_block.obj, model: mass_spring_surface, "                \
  "position: [0, 0, 0.032]}\ntools:\n  - {name: knife, kind: scalpel, radius: 0.001}\n"

static void test_cut_ms(void) {
  CHECK(load(&a, BLOCK_MS));
  size_t nv0 = a.organs[0].model->nsurf;
  double above[3] = {-0.02, 0, 0.058}, in0[3] = {-0.02, 0, 0.030}, mid[3] = {0.0, 0, 0.030};
  drive(&a, 0, above, in0, 200, 1);
  drive(&a, 0, in0, mid, 200, 1);
  drive(&a, 0, mid, above, 100, 0);
  const model_t *ma = a.organs[0].model;
  CHECK(ma->topology_version > 0 && ma->nsurf != nv0);
  CHECK(checkpoint_save(path, &a, ta, NULL, &err) == 0);
  CHECK(load(&b, BLOCK_MS));
  int r = checkpoint_load(path, &b, tb, NULL, &err);
  if (r != 1) fprintf(stderr, "  %s\n", err.msg);
  CHECK(r == 1);
  const model_t *mb = b.organs[0].model;
  CHECK(same_model(ma, mb) && mb->substeps == ma->substeps);
  CHECK(b.organs[0].topology_version == mb->topology_version && b.organs[0].tree.ntris == mb->nsurf_tris);
  /* Both go on: the restored one stays finite without rollbacks (its
   * sub-step re-estimates are not saved, so the two may part in the last
   * bits later). */
  drive(&a, 0, above, above, 200, 0);
  drive(&b, 0, above, above, 200, 0);
  double d = 0;
  int finite = 1;
  for (size_t i = 0; i < 3 * mb->nsurf; i++) {
    finite &= isfinite(mb->surf_x[i]);
    if (mb->nsurf == ma->nsurf) d = fmax(d, fabs(ma->surf_x[i] - mb->surf_x[i]));
  }
  CHECK(finite && b.organs[0].rollbacks == 0);
  printf("cut mass-spring block: %zu -> %zu nodes, topology %u, %d sub-steps; restored equal, after 200 more steps "
         "max difference %.3g m\n",
         nv0, ma->nsurf, ma->topology_version, ma->substeps, d);
  /* A crafted triangle index behind a valid CRC: refused, b rebuilt at rest. */
  unsigned char *bytes = NULL;
  size_t n = read_file(path, &bytes);
  if (n > 1000) {
    uint64_t nn, ntris;
    const size_t nn_at = 8 + SCENE_NAME_LEN + 8 + 8 + 8;
    memcpy(&nn, bytes + nn_at, 8);
    size_t blob_at = nn_at + 16 + 48 * nn + 8;
    memcpy(&ntris, bytes + blob_at + 8, 8);
    uint64_t has_fres;
    memcpy(&has_fres, bytes + blob_at + 16 + 40 * nn, 8);
    size_t tri_at = blob_at + 16 + 40 * nn + 8 + (has_fres ? 24 * nn : 0);
    uint32_t big = (uint32_t)nn + 5;
    memcpy(bytes + tri_at + 4, &big, 4);
    write_bad(bytes, n - 8, 1);
    CHECK(checkpoint_load(bad, &b, tb, NULL, &err) == -1);
    CHECK(strstr(err.msg, "triangle") && strstr(err.msg, "starting from rest"));
    CHECK(b.steps == 0 && b.organs[0].model->topology_version == 0 && b.organs[0].model->nsurf == nv0);
  }
  free(bytes);
  runtime_destroy(&a);
  runtime_destroy(&b);
}

/* The adaptive kidney refined under a probe: restored with the same
 * refined mesh bit for bit, and both then run on identically (probe
 * released: the refinement is kept for release_time, then simplified). A
 * crafted refinement centre is refused. */
static int load_adaptive(runtime_t *rt) {
  if (!test_runtime_load_scene(rt, &sc, "kidney_adaptive.yaml", &err)) return 0;
  for (size_t t = 0; t < rt->ntools; t++) thr_init(rt == &a ? &ta[t].thr : &tb[t].thr, 0, 0, 0);
  return 1;
}

static void test_adaptive(void) {
  CHECK(load_adaptive(&a));
  size_t nv0 = a.organs[0].model->nsurf;
  double dev[3] = {0.012, 0.004, 0.045};
  for (int s = 0; s < 3000 && a.organs[0].model->topology_version == 0; s++) {
    dev[2] -= 1e-5;
    runtime_set_tool(&a, 0, dev, 4);
    runtime_step(&a);
    a.events.n = 0;
  }
  const model_t *ma = a.organs[0].model;
  CHECK(ma->topology_version > 0 && ma->nsurf > nv0);
  CHECK(checkpoint_save(path, &a, ta, NULL, &err) == 0);
  CHECK(load_adaptive(&b));
  int r = checkpoint_load(path, &b, tb, NULL, &err);
  if (r != 1) fprintf(stderr, "  %s\n", err.msg);
  CHECK(r == 1);
  const model_t *mb = b.organs[0].model;
  CHECK(same_model(ma, mb) && mb->substeps == ma->substeps);
  size_t ns_saved = mb->nsurf;
  uint32_t tv_saved = mb->topology_version;
  runtime_release_tool(&a, 0);
  for (int s = 0; s < 300; s++) {
    runtime_step(&a);
    runtime_step(&b);
  }
  CHECK(same_model(ma, mb));
  printf("adaptive kidney: %zu -> %zu surface vertices (topology %u) restored bit for bit; after 300 more steps "
         "(probe released) %zu vertices, topology %u in both\n",
         nv0, ns_saved, tv_saved, ma->nsurf, ma->topology_version);
  unsigned char *bytes = NULL;
  size_t n = read_file(path, &bytes);
  if (n > 200) {
    uint64_t nn;
    const size_t nn_at = 8 + SCENE_NAME_LEN + 8 + 8 + 8;
    memcpy(&nn, bytes + nn_at, 8);
    size_t centre_at = nn_at + 16 + 48 * nn + 8 + 8;
    uint64_t c = 1u << 30;
    memcpy(bytes + centre_at, &c, 8);
    write_bad(bytes, n - 8, 1);
    runtime_destroy(&b);
    CHECK(load_adaptive(&b));
    CHECK(checkpoint_load(bad, &b, tb, NULL, &err) == -1);
    CHECK(strstr(err.msg, "bad centre") != NULL);
    CHECK(b.organs[0].model->topology_version == 0 && b.organs[0].model->nsurf == nv0);
  }
  free(bytes);
  runtime_destroy(&a);
  runtime_destroy(&b);
}

int main(void) {
  snprintf(path, sizeof path, "/tmp/viscera_test_ckstate_%d.bin", (int)getpid());
  snprintf(bad, sizeof bad, "%s.bad", path);
  test_objects_tasks_tallies();
  test_cut_xpbd();
  test_cut_ms();
  test_adaptive();
  unlink(path);
  unlink(bad);
  return check_report("test_checkpoint_state");
}
