/* SPDX-License-Identifier: Apache-2.0 */
/* Tool command validation (runtime/tool_command.h): NaN, Inf, absurd positions, bad quaternions, bad
 * ids and capabilities are rejected; a sane command passes. */
#include <string.h>

#include "check.h"
#include "runtime/tool_command.h"

int main(void) {
  tool_workspace_t ws = {{-1, -1, -1}, {1, 1, 1}};
  tool_cmd_t c;
  memset(&c, 0, sizeof c);
  c.orientation[0] = 1;
  c.max_force = 4;
  c.position[2] = 0.05f;
  CHECK(tool_command_check(&c, 1, &ws) == TOOLCMD_OK);
  tool_cmd_t b = c;
  b.tool_id = 1;
  CHECK(tool_command_check(&b, 1, &ws) == TOOLCMD_BAD_ID);
  b = c;
  b.position[0] = NAN;
  CHECK(tool_command_check(&b, 1, &ws) == TOOLCMD_NONFINITE);
  b = c;
  b.position[1] = INFINITY;
  CHECK(tool_command_check(&b, 1, &ws) == TOOLCMD_NONFINITE);
  b = c;
  b.orientation[2] = NAN;
  CHECK(tool_command_check(&b, 1, &ws) == TOOLCMD_NONFINITE);
  b = c;
  b.position[2] = 1e30f;
  CHECK(tool_command_check(&b, 1, &ws) == TOOLCMD_OUT_OF_WORKSPACE);
  b = c;
  b.orientation[0] = 2;
  CHECK(tool_command_check(&b, 1, &ws) == TOOLCMD_BAD_ORIENTATION);
  b = c;
  b.max_force = -1;
  CHECK(tool_command_check(&b, 1, &ws) == TOOLCMD_BAD_MAX_FORCE);
  b.max_force = 1e6f;
  CHECK(tool_command_check(&b, 1, &ws) == TOOLCMD_BAD_MAX_FORCE);
  CHECK(strcmp(tool_command_verdict_str(TOOLCMD_NONFINITE), "ok") != 0);
  return check_report("test_tool_command");
}
