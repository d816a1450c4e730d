/* SPDX-License-Identifier: Apache-2.0 */
/* impostor: a participant that is not the seat's server publishing the
 * server's topics (issue 15.2), and the checker of what the seat's clients
 * made of it.
 *
 * impostor run DOMAIN PARTITION ROLE SECONDS
 *   Announces role ROLE (vdds_ident.h) and, for SECONDS, writes at 1 kHz a
 *   ContactFeedback for tool 0 that pulls the hand 4 N into the tissue
 *   (in contact, stiffness and force within the default scene's limits, so
 *   only the identity check can refuse it), and at 20 Hz a forged MeshState
 *   (a small tetrahedron 0.2 m away, keyframe 99) and MeshDelta for organ
 *   0. Never writes SceneInfo.
 *
 * impostor check FORCE_CSV HAPTIC_OUT VIEWER_OUT
 *   The trainee's force log never shows a force (its hand stays in free
 *   space, so any force is forged); its FEEDBACK line counts ignored
 *   samples (ignored, then dropped at the gate) and real ones received;
 *   the viewer's SUMMARY counts ignored samples. The viewer's mesh is compared with the server's by
 *   obj_compare in the script. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "dds/vdds.h"
#include "viscera.h"
#include "vtime.h"

static int run(char **argv) {
  vdds_set_role(argv[4]);
  double seconds = atof(argv[5]);
  vdds_t v;
  verr_t err;
  if (vdds_open(&v, cli_parse_domain(argv[2]), argv[3], &err)) {
    fprintf(stderr, "impostor: %s\n", err.msg);
    return 1;
  }
  dds_entity_t w_fb = vdds_writer(&v, VT_CONTACT_FEEDBACK, &err);
  dds_entity_t w_state = vdds_writer(&v, VT_MESH_STATE, &err);
  dds_entity_t w_delta = vdds_writer(&v, VT_MESH_DELTA, &err);
  if (w_fb < 0 || w_state < 0 || w_delta < 0) {
    fprintf(stderr, "impostor: %s\n", err.msg);
    return 1;
  }
  float pos[12] = {0.2f, 0, 0, 0.21f, 0, 0, 0.2f, 0.01f, 0, 0.2f, 0, 0.01f};
  uint32_t tris[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  uint32_t idx[1] = {0};
  int16_t dq[3] = {1000, 1000, 1000};
  uint64_t t0 = vtime_mono_ns(), next = t0, n_fb = 0, n_mesh = 0;
  while (vtime_mono_ns() - t0 < (uint64_t)(seconds * 1e9)) {
    viscera_ContactFeedback fb;
    memset(&fb, 0, sizeof fb);
    fb.tool_id = 0;
    fb.seq = UINT64_MAX - 1; /* "newest" forever, were it believed */
    fb.in_contact = 1;
    fb.organ_id = 0;
    /* A plane 1 cm below the trainee's hand (held at z = 0.07 m) facing
     * down: F = k d n = 400 N/m x 0.01 m, a 4 N pull down into the kidney. */
    fb.proxy_position[1] = 0.004f;
    fb.proxy_position[2] = 0.06f;
    fb.normal[2] = -1;
    fb.stiffness = 400;
    fb.force[2] = -4;
    if (dds_write(w_fb, &fb) >= 0) n_fb++;
    if (n_fb % 50 == 1) {
      viscera_MeshState ms;
      memset(&ms, 0, sizeof ms);
      ms.topology_version = 1;
      ms.keyframe_seq = 99;
      ms.sim_time_ns = vtime_mono_ns() - t0;
      ms.positions._buffer = pos;
      ms.positions._length = ms.positions._maximum = 12;
      ms.triangles._buffer = tris;
      ms.triangles._length = ms.triangles._maximum = 12;
      viscera_MeshDelta md;
      memset(&md, 0, sizeof md);
      md.topology_version = 1;
      md.keyframe_seq = 99;
      md.frame_seq = (uint32_t)n_mesh;
      md.quant_step = 1e-5f;
      md.indices._buffer = idx;
      md.indices._length = md.indices._maximum = 1;
      md.dq._buffer = dq;
      md.dq._length = md.dq._maximum = 3;
      if (dds_write(w_state, &ms) >= 0 && dds_write(w_delta, &md) >= 0) n_mesh++;
    }
    next += 1000000;
    vtime_sleep_until(next);
  }
  printf("IMPOSTOR feedback=%llu meshes=%llu\n", (unsigned long long)n_fb, (unsigned long long)n_mesh);
  vdds_close(&v);
  return 0;
}

/* The value of `key=` on the first line of `path` starting with `tag`. */
static int field(const char *path, const char *tag, const char *key, double *out) {
  FILE *f = fopen(path, "r");
  char line[2048], pat[64];
  int found = 0;
  if (!f) return -1;
  snprintf(pat, sizeof pat, " %s=", key);
  while (!found && fgets(line, sizeof line, f)) {
    const char *p = strncmp(line, tag, strlen(tag)) == 0 ? strstr(line, pat) : NULL;
    if (p) found = sscanf(p + strlen(pat), "%lf", out) == 1;
  }
  fclose(f);
  if (!found) fprintf(stderr, "impostor: no %s= on a %s line of %s\n", key, tag, path);
  return found ? 0 : -1;
}

static int check(char **argv) {
  FILE *f = fopen(argv[2], "r");
  if (!f) {
    fprintf(stderr, "impostor: cannot read %s\n", argv[2]);
    return 1;
  }
  char line[512];
  double peak = 0;
  long rows = 0, in_contact_rows = 0;
  while (fgets(line, sizeof line, f)) {
    double t, x, y, z, fx, fy, fz;
    int c;
    if (sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%d", &t, &x, &y, &z, &fx, &fy, &fz, &c) != 8) continue;
    rows++;
    in_contact_rows += c != 0;
    double m = sqrt(fx * fx + fy * fy + fz * fz);
    if (m > peak) peak = m;
  }
  fclose(f);
  /* Ignored once judged, then dropped at the reader's gate (blocked). */
  double ignored = 0, gated = 0, received = 0, v_ignored = 0, v_gated = 0;
  if (field(argv[3], "FEEDBACK", "ignored", &ignored) || field(argv[3], "FEEDBACK", "received", &received) ||
      field(argv[3], "FEEDBACK", "gate_dropped", &gated) || field(argv[4], "SUMMARY", "ignored", &v_ignored) ||
      field(argv[4], "SUMMARY", "gate_dropped", &v_gated))
    return 1;
  ignored += gated;
  v_ignored += v_gated;
  printf("trainee: %ld ticks logged, peak force %.4f N, %ld ticks in contact; feedback %.0f used, %.0f ignored; "
         "viewer: %.0f ignored\n",
         rows, peak, in_contact_rows, received, ignored, v_ignored);
  int bad = 0;
  if (rows < 100) bad = fprintf(stderr, "FAIL: the force log has only %ld rows\n", rows);
  if (peak > 0 || in_contact_rows > 0)
    bad = fprintf(stderr, "FAIL: the trainee felt a forged force (peak %.4f N, %ld ticks)\n", peak, in_contact_rows);
  if (ignored < 100) bad = fprintf(stderr, "FAIL: the haptic client did not count the forged feedback ignored\n");
  if (received < 100) bad = fprintf(stderr, "FAIL: the haptic client used no feedback of its server\n");
  if (v_ignored < 1) bad = fprintf(stderr, "FAIL: the viewer did not count the forged samples ignored\n");
  return bad ? 1 : 0;
}

int main(int argc, char **argv) {
  if (argc == 6 && strcmp(argv[1], "run") == 0) return run(argv);
  if (argc == 5 && strcmp(argv[1], "check") == 0) return check(argv);
  fprintf(stderr, "usage: impostor run DOMAIN PARTITION ROLE SECONDS\n"
                  "       impostor check FORCE_CSV HAPTIC_OUT VIEWER_OUT\n");
  return 2;
}
