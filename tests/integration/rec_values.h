/* SPDX-License-Identifier: Apache-2.0 */
/* rec_values: what rec_pub publishes, so rec_check can verify a recording
 * against it. Shared by the recorder integration test programs only. */
#ifndef VISCERA_TEST_REC_VALUES_H
#define VISCERA_TEST_REC_VALUES_H

#include <stdint.h>

#include "viscera.h"

#define REC_TEST_TOOL_ID 3u
#define REC_TEST_DISPOSED_ORGAN 1u
#define REC_TEST_KEYFRAME_VERTICES 120u

/* The i-th ToolCommand: every field depends on i so a decode that mixes up
 * fields or samples is caught. Values are exact in float. */
static inline viscera_ToolCommand rec_test_tool_command(uint32_t i) {
  viscera_ToolCommand c;
  c.tool_id = REC_TEST_TOOL_ID;
  c.seq = i;
  c.client_mono_ns = 1000000000ull + 1000ull * i;
  c.position[0] = 0.25f * (float)i;
  c.position[1] = -0.5f * (float)i;
  c.position[2] = 0.125f;
  c.orientation[0] = 0.5f;
  c.orientation[1] = -0.5f;
  c.orientation[2] = 0.5f;
  c.orientation[3] = (i % 2) ? 0.5f : -0.5f;
  c.buttons = i & 3u;
  c.max_force = 3.5f + (float)(i % 7);
  return c;
}

#endif
