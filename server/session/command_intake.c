/* SPDX-License-Identifier: Apache-2.0 */
#include "session/command_intake.h"

void command_from_dds(const viscera_ToolCommand *in, tool_cmd_t *out) {
  out->tool_id = in->tool_id;
  for (int k = 0; k < 3; k++) out->position[k] = in->position[k];
  for (int k = 0; k < 4; k++) out->orientation[k] = in->orientation[k];
  out->buttons = in->buttons;
  out->max_force = in->max_force;
  out->seq = in->seq;
  out->echo = in->client_mono_ns;
}

int command_gate_check(const void *sample, void *arg) {
  const command_gate_t *g = arg;
  tool_cmd_t c;
  command_from_dds(sample, &c);
  return (int)tool_command_check(&c, g->ntools, &g->workspace);
}
