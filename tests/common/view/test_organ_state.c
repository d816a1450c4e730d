/* SPDX-License-Identifier: Apache-2.0 */
/* test_organ_state: the viewer's keyframe + delta reconstruction on plain
 * arrays: matching rules, a delta waiting for its keyframe, untrusted input
 * never changing what is drawn, and topology versions: a new keyframe
 * replaces the mesh, stale deltas are ignored, a delta for a newer version
 * waits for its keyframe even when they arrive out of order. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "view/organ_state.h"

static const float KEY[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
static const uint32_t TRIS[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};

static organ_delta_t delta(uint32_t kseq, uint32_t frame, const uint32_t *idx, size_t n, const int16_t *dq) {
  return (organ_delta_t){.topology_version = 1,
                         .keyframe_seq = kseq,
                         .frame_seq = frame,
                         .sim_time_ns = 1000 + frame,
                         .quant_step = 0.5f,
                         .indices = idx,
                         .count = n,
                         .dq = dq,
                         .dq_len = 3 * n};
}

/* An octahedron: what a refined version of the tetrahedron looks like to the viewer. */
static const float OCTA[18] = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
static const uint32_t OCTA_TRIS[24] = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};

static organ_delta_t vdelta(uint32_t topo, uint32_t kseq, uint32_t frame, const uint32_t *idx, size_t n,
                            const int16_t *dq) {
  return (organ_delta_t){.topology_version = topo,
                         .keyframe_seq = kseq,
                         .frame_seq = frame,
                         .sim_time_ns = frame,
                         .quant_step = 0.5f,
                         .indices = idx,
                         .count = n,
                         .dq = dq,
                         .dq_len = 3 * n};
}

static void test_topology(void) {
  organ_state_t o = {0};
  verr_t err;
  const uint32_t i1[1] = {1}, i5[1] = {5};
  const int16_t up[3] = {0, 0, 2}; /* z += 1.0 */
  /* Version 0: the tetrahedron with a delta. */
  CHECK(organ_state_set_keyframe(&o, 0, 1, 0, KEY, 12, TRIS, 12, &err) == 0);
  organ_delta_t d = vdelta(0, 1, 10, i1, 1, up);
  CHECK(organ_state_delta(&o, &d, &err) == 1 && o.cur[5] == 1.0f);
  /* Version 1 (refined): the new keyframe replaces the mesh whole. */
  CHECK(organ_state_set_keyframe(&o, 1, 2, 0, OCTA, 18, OCTA_TRIS, 24, &err) == 0);
  CHECK(o.nverts == 6 && o.ntris == 8 && o.topology_version == 1 && organ_state_frame_seq(&o) == -1);
  CHECK(memcmp(o.cur, OCTA, sizeof OCTA) == 0 && memcmp(o.tris, OCTA_TRIS, sizeof OCTA_TRIS) == 0);
  /* A late delta of version 0 is stale: ignored, the mesh as it was. */
  d = vdelta(0, 1, 11, i1, 1, up);
  CHECK(organ_state_delta(&o, &d, &err) == 2 && memcmp(o.cur, OCTA, sizeof OCTA) == 0);
  /* Version 1's own delta moves vertex 5, which version 0 did not have. */
  d = vdelta(1, 2, 12, i5, 1, up);
  CHECK(organ_state_delta(&o, &d, &err) == 1 && o.cur[17] == 0.0f && organ_state_frame_seq(&o) == 12);
  /* Out of order across topics: version 2's delta before its keyframe
   * waits; the drawn mesh stays version 1 with its delta. */
  d = vdelta(2, 3, 13, i1, 1, up);
  CHECK(organ_state_delta(&o, &d, &err) == 0 && o.nverts == 6 && organ_state_frame_seq(&o) == 12);
  /* A stale version-1 delta naming vertex 5 is ignored, not an error, and
   * does not displace the waiting version-2 delta. */
  d = vdelta(1, 2, 12, i5, 1, up);
  CHECK(organ_state_set_keyframe(&o, 2, 3, 0, KEY, 12, TRIS, 12, &err) == 0); /* version 2: simplified */
  CHECK(o.nverts == 4 && o.ntris == 4 && organ_state_frame_seq(&o) == 13 && o.cur[5] == 1.0f);
  CHECK(organ_state_delta(&o, &d, &err) == 2 && organ_state_frame_seq(&o) == 13);
  /* Same version, older keyframe_seq: stale too. */
  CHECK(organ_state_set_keyframe(&o, 2, 4, 0, KEY, 12, TRIS, 12, &err) == 0);
  d = vdelta(2, 3, 14, i1, 1, up);
  CHECK(organ_state_delta(&o, &d, &err) == 2 && organ_state_frame_seq(&o) == -1);
  /* A keyframe drops a kept delta older than itself. */
  d = vdelta(3, 5, 15, i1, 1, up);
  CHECK(organ_state_delta(&o, &d, &err) == 0 && o.have_delta);
  CHECK(organ_state_set_keyframe(&o, 4, 6, 0, OCTA, 18, OCTA_TRIS, 24, &err) == 0 && !o.have_delta);
  CHECK(organ_state_frame_seq(&o) == -1 && o.nverts == 6);
  /* A restarted server counts from 0 again: its keyframe is drawn. */
  CHECK(organ_state_set_keyframe(&o, 0, 1, 0, KEY, 12, TRIS, 12, &err) == 0 && o.nverts == 4);
  d = vdelta(0, 1, 1, i1, 1, up);
  CHECK(organ_state_delta(&o, &d, &err) == 1 && o.cur[5] == 1.0f);
  organ_state_free(&o);
}

int main(void) {
  test_topology();
  organ_state_t o = {0};
  verr_t err;
  const uint32_t i1[1] = {1};
  const int16_t d1[3] = {2, 0, 0}; /* vertex 1 x += 1.0 */

  /* A delta before its keyframe is kept, then applied when it arrives. */
  organ_delta_t d = delta(4, 7, i1, 1, d1);
  CHECK(organ_state_delta(&o, &d, &err) == 0);
  CHECK(!o.have_key);
  CHECK(organ_state_set_keyframe(&o, 1, 4, 500, KEY, 12, TRIS, 12, &err) == 0);
  CHECK(organ_state_frame_seq(&o) == 7);
  CHECK_NEAR(o.cur[3], 2.0, 0);
  CHECK_NEAR(o.key[3], 1.0, 0);
  CHECK(o.sim_time_ns == 1007);

  /* A delta for another keyframe or topology does not touch the mesh. */
  const int16_t d2[3] = {0, 4, 0};
  d = delta(5, 8, i1, 1, d2);
  CHECK(organ_state_delta(&o, &d, &err) == 0);
  d.keyframe_seq = 4, d.topology_version = 2;
  CHECK(organ_state_delta(&o, &d, &err) == 0);
  CHECK(organ_state_frame_seq(&o) == 7 && o.cur[3] == 2.0f && o.cur[4] == 0.0f);
  /* The matching one applies cumulatively against the keyframe. */
  d = delta(4, 9, i1, 1, d2);
  CHECK(organ_state_delta(&o, &d, &err) == 1);
  CHECK(o.cur[3] == 1.0f && o.cur[4] == 2.0f && organ_state_frame_seq(&o) == 9);

  /* Bad deltas are rejected with a reason and leave the drawn mesh alone. */
  const uint32_t bad_idx[2] = {3, 1};
  const int16_t dq6[6] = {1, 1, 1, 1, 1, 1};
  d = delta(4, 10, bad_idx, 2, dq6);
  CHECK(organ_state_delta(&o, &d, &err) == -1 && strstr(err.msg, "ascending"));
  const uint32_t oor[1] = {99};
  d = delta(4, 11, oor, 1, dq6);
  CHECK(organ_state_delta(&o, &d, &err) == -1 && strstr(err.msg, "out of range"));
  d = delta(4, 12, i1, 1, dq6);
  d.dq_len = 2;
  CHECK(organ_state_delta(&o, &d, &err) == -1);
  d = delta(4, 13, i1, 1, dq6);
  d.quant_step = NAN;
  CHECK(organ_state_delta(&o, &d, &err) == -1);
  CHECK(o.cur[3] == 1.0f && o.cur[4] == 2.0f && organ_state_frame_seq(&o) == 9);

  /* Bad keyframes are rejected and the previous one stays. */
  const uint32_t bad_tris[3] = {0, 1, 4};
  float nan_key[12];
  memcpy(nan_key, KEY, sizeof nan_key);
  nan_key[7] = NAN;
  CHECK(organ_state_set_keyframe(&o, 1, 6, 0, KEY, 12, bad_tris, 3, &err) == -1 && strstr(err.msg, "vertex 4"));
  CHECK(organ_state_set_keyframe(&o, 1, 6, 0, KEY, 11, TRIS, 12, &err) == -1);
  CHECK(organ_state_set_keyframe(&o, 1, 6, 0, KEY, 12, TRIS, 11, &err) == -1);
  CHECK(organ_state_set_keyframe(&o, 1, 6, 0, KEY, 0, TRIS, 12, &err) == -1);
  CHECK(organ_state_set_keyframe(&o, 1, 6, 0, nan_key, 12, TRIS, 12, &err) == -1 && strstr(err.msg, "non-finite"));
  CHECK(o.keyframe_seq == 4 && organ_state_frame_seq(&o) == 9 && o.cur[4] == 2.0f);

  /* A new keyframe without its delta is drawn bare; a kept delta that fails
   * against its keyframe is reported and the keyframe still accepted. */
  /* Only the newest delta is kept: (5, 8) from above was superseded. */
  CHECK(organ_state_set_keyframe(&o, 1, 5, 0, KEY, 12, TRIS, 12, &err) == 0);
  CHECK(organ_state_frame_seq(&o) == -1);
  d = delta(6, 20, i1, 1, d2);
  CHECK(organ_state_delta(&o, &d, &err) == 0);
  CHECK(organ_state_set_keyframe(&o, 1, 5, 0, KEY, 12, TRIS, 12, &err) == 0); /* (6, 20) waits */
  CHECK(organ_state_frame_seq(&o) == -1 && o.cur[4] == 0.0f);
  CHECK(organ_state_set_keyframe(&o, 1, 6, 0, KEY, 12, TRIS, 12, &err) == 0);
  CHECK(organ_state_frame_seq(&o) == 20 && o.cur[4] == 2.0f);
  d = delta(7, 1, oor, 1, dq6);
  CHECK(organ_state_delta(&o, &d, &err) == 0);
  CHECK(organ_state_set_keyframe(&o, 1, 7, 0, KEY, 12, TRIS, 12, &err) == 1 && strstr(err.msg, "out of range"));
  CHECK(o.have_key && o.keyframe_seq == 7 && organ_state_frame_seq(&o) == -1);

  organ_state_free(&o);
  return check_report("test_organ_state");
}
