/* SPDX-License-Identifier: Apache-2.0 */
/* mesh_publisher quiet frames (encode only, no DDS writers): with
 * keepalive_ns > 0 a frame whose quantised delta equals the last written
 * one is skipped (frames and frame_seq stay, skipped counts it) unless the
 * keepalive of wall time has passed; a move by less than half a quantisation
 * step is no change, a move by two steps is; a keyframe (range overflow)
 * restarts the comparison so the next delta is written; keepalive_ns = 0
 * writes every frame (the old behaviour). */
#define _POSIX_C_SOURCE 200809L
#include <string.h>
#include <time.h>

#include "check.h"
#include "session/mesh_publisher.h"

#define Q 1e-5f
enum { N = 6 };

static void pause_ms(long ms) {
  struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
  nanosleep(&ts, NULL);
}

int main(void) {
  double x[3 * N];
  uint32_t tris[6] = {0, 1, 2, 3, 4, 5};
  for (int i = 0; i < 3 * N; i++) x[i] = 0.01 * i;
  mesh_publisher_t mp;
  verr_t err;
  CHECK(mesh_publisher_init(&mp, 0, N, tris, 2, Q, 0, 0, &err) == 0);
  mp.keepalive_ns = 200000000ull; /* 200 ms */
  CHECK(mesh_publisher_keyframe(&mp, x, 0) == 0);
  /* First delta after a keyframe: written (nothing to compare with). */
  CHECK(mesh_publisher_frame(&mp, x, 1) == 0);
  CHECK(mp.frames == 1 && mp.frame_seq == 1 && mp.skipped == 0);
  /* Unchanged: skipped, twice. */
  CHECK(mesh_publisher_frame(&mp, x, 2) == 0);
  CHECK(mesh_publisher_frame(&mp, x, 3) == 0);
  CHECK(mp.frames == 1 && mp.frame_seq == 1 && mp.skipped == 2);
  /* A move by 0.4 q rounds to the same step: still no change. */
  x[4] += 0.4 * Q;
  CHECK(mesh_publisher_frame(&mp, x, 4) == 0);
  CHECK(mp.frames == 1 && mp.skipped == 3);
  /* Two steps: written, and the delta names vertex 1. */
  x[4] += 2.0 * Q;
  CHECK(mesh_publisher_frame(&mp, x, 5) == 0);
  CHECK(mp.frames == 2 && mp.frame_seq == 2 && mp.skipped == 3);
  CHECK(mp.last_count == 1 && mp.idx[0] == 1);
  /* Back to the keyframe position: a different delta (empty), written. */
  x[4] -= 2.4 * Q;
  CHECK(mesh_publisher_frame(&mp, x, 6) == 0);
  CHECK(mp.frames == 3 && mp.last_count == 0);
  CHECK(mesh_publisher_frame(&mp, x, 7) == 0);
  CHECK(mp.frames == 3 && mp.skipped == 4);
  /* The keepalive: after 250 ms the same delta goes out again. */
  pause_ms(250);
  CHECK(mesh_publisher_frame(&mp, x, 8) == 0);
  CHECK(mp.frames == 4 && mp.frame_seq == 4 && mp.skipped == 4);
  CHECK(mesh_publisher_frame(&mp, x, 9) == 0);
  CHECK(mp.frames == 4 && mp.skipped == 5);
  /* Out of int16 range: a keyframe, and with it a (empty) delta of the new
   * keyframe is written although the last written delta was empty too. */
  x[0] += 1.0;
  uint64_t f = mp.frames;
  CHECK(mesh_publisher_frame(&mp, x, 10) == 1);
  CHECK(mp.keyframes == 2 && mp.frames == f + 1 && mp.last_count == 0);
  CHECK(mesh_publisher_frame(&mp, x, 11) == 0);
  CHECK(mesh_publisher_frame(&mp, x, 12) == 0);
  CHECK(mp.frames == f + 1 && mp.skipped == 7);
  /* keepalive 0: every frame written. */
  mp.keepalive_ns = 0;
  for (int i = 0; i < 3; i++) CHECK(mesh_publisher_frame(&mp, x, 13 + (uint64_t)i) == 0);
  CHECK(mp.frames == f + 4 && mp.skipped == 7);
  mesh_publisher_destroy(&mp);
  return check_report("test_publisher_quiet");
}
