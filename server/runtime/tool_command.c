/* SPDX-License-Identifier: Apache-2.0 */
#include "runtime/tool_command.h"

#include <math.h>

tool_cmd_verdict_t tool_command_check(const tool_cmd_t *c, size_t ntools, const tool_workspace_t *ws) {
  if (c->tool_id >= ntools) return TOOLCMD_BAD_ID;
  for (int k = 0; k < 3; k++)
    if (!isfinite(c->position[k])) return TOOLCMD_NONFINITE;
  for (int k = 0; k < 4; k++)
    if (!isfinite(c->orientation[k])) return TOOLCMD_NONFINITE;
  if (!isfinite(c->max_force)) return TOOLCMD_NONFINITE;
  for (int k = 0; k < 3; k++)
    if (c->position[k] < ws->min[k] || c->position[k] > ws->max[k]) return TOOLCMD_OUT_OF_WORKSPACE;
  double q2 = 0;
  for (int k = 0; k < 4; k++) q2 += (double)c->orientation[k] * c->orientation[k];
  if (fabs(q2 - 1.0) > 0.01) return TOOLCMD_BAD_ORIENTATION;
  /* Real devices top out around 40 N; 1 kN is a corrupt sample, not a device. */
  if (!(c->max_force > 0) || c->max_force > 1000) return TOOLCMD_BAD_MAX_FORCE;
  return TOOLCMD_OK;
}

const char *tool_command_verdict_str(tool_cmd_verdict_t v) {
  switch (v) {
  case TOOLCMD_OK: return "ok";
  case TOOLCMD_BAD_ID: return "tool id out of range";
  case TOOLCMD_NONFINITE: return "non-finite value (NaN or Inf)";
  case TOOLCMD_OUT_OF_WORKSPACE: return "position outside the workspace";
  case TOOLCMD_BAD_ORIENTATION: return "orientation is not a unit quaternion";
  case TOOLCMD_BAD_MAX_FORCE: return "max_force not in (0, 1000] N";
  case TOOLCMD_NOT_ASSIGNED: return "tool assigned to another station";
  default: return "?";
  }
}

void tool_input_from_cmd(const tool_cmd_t *c, tool_input_t *out) {
  *out = (tool_input_t){.pos = {c->position[0], c->position[1], c->position[2]},
                        .q = {c->orientation[0], c->orientation[1], c->orientation[2], c->orientation[3]},
                        .buttons = c->buttons,
                        .max_force = c->max_force,
                        .seq = c->seq,
                        .echo = c->echo};
}
