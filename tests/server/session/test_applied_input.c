/* SPDX-License-Identifier: Apache-2.0 */
/* applied_input (server/session/applied_input.h), without DDS (writer 0):
 * entries keep the server's order (commands and releases, then controls),
 * exactly the effective command's fields; the header is the state when the
 * first entry came, so a control's rebuild does not move it (begin_control
 * first) and the next sample carries the new epoch and step; a full buffer
 * starts a new sample; samples are numbered from 1 (a gap is a lost one). */
#include <string.h>

#include "check.h"
#include "session/applied_input.h"

int main(void) {
  static runtime_t rt; /* only steps and sim_time are read */
  int paused = 0;
  applied_input_t ai;
  applied_input_init(&ai, 0, &rt, &paused);
  rt.steps = 5;
  rt.sim_time = 0.005;
  applied_input_tick(&ai);
  CHECK(ai.tick == 1 && !ai.open);
  tool_input_t in = {.pos = {0.1, -0.2, 0.3}, .q = {1, 0, 0, 0}, .buttons = 1, .max_force = 3.5, .seq = 42, .echo = 7};
  applied_input_command(&ai, 1, &in);
  applied_input_release(&ai, 0);
  CHECK(ai.open && ai.cur.tick == 1 && ai.cur.step == 5 && ai.cur.sim_time_ns == 5000000 && ai.cur.epoch == 0);
  CHECK(ai.cur.tools._length == 2);
  CHECK(ai.tools[0].tool_id == 1 && !ai.tools[0].released && ai.tools[0].position[1] == -0.2 &&
        ai.tools[0].orientation[0] == 1 && ai.tools[0].buttons == 1 && ai.tools[0].max_force == 3.5 &&
        ai.tools[0].cmd_seq == 42 && ai.tools[0].cmd_client_mono_ns == 7);
  CHECK(ai.tools[1].tool_id == 0 && ai.tools[1].released);
  /* A reset: the control is begun before the rebuild, recorded after it. */
  viscera_SessionControl c;
  memset(&c, 0, sizeof c);
  c.kind = viscera_CONTROL_RESET;
  c.tool_id = -1;
  c.organ_id = -1;
  applied_input_begin_control(&ai);
  rt.steps = 0;
  rt.sim_time = 0;
  applied_input_rebuilt(&ai);
  applied_input_control(&ai, &c, 1, -1);
  CHECK(ai.cur.step == 5 && ai.cur.epoch == 0 && ai.cur.controls._length == 1);
  CHECK(ai.controls[0].kind == viscera_CONTROL_RESET && ai.controls[0].result == 1 && ai.controls[0].task == -1);
  applied_input_tick(&ai); /* publishes (nothing to write to) and closes */
  CHECK(!ai.open && ai.tick == 2 && ai.seq == 1 && ai.cur.seq == 1);
  paused = 1;
  applied_input_command(&ai, 0, &in);
  CHECK(ai.cur.step == 0 && ai.cur.epoch == 1 && ai.cur.paused && ai.cur.tick == 2);
  /* Full: the entry after APPLIED_MAX_TOOLS opens a new sample. */
  for (int i = 1; i < APPLIED_MAX_TOOLS; i++) applied_input_command(&ai, 0, &in);
  CHECK(ai.cur.tools._length == APPLIED_MAX_TOOLS);
  rt.steps = 3;
  applied_input_release(&ai, 1);
  CHECK(ai.cur.tools._length == 1 && ai.tools[0].released && ai.cur.step == 3);
  applied_input_flush(&ai);
  CHECK(!ai.open && ai.published == 0 && ai.failed == 0 && ai.seq == 3);
  return check_report("test_applied_input");
}
