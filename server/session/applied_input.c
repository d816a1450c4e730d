/* SPDX-License-Identifier: Apache-2.0 */
#include "session/applied_input.h"

#include <string.h>

void applied_input_init(applied_input_t *ai, dds_entity_t writer, const runtime_t *rt, const int *paused) {
  memset(ai, 0, sizeof *ai);
  ai->writer = writer;
  ai->rt = rt;
  ai->paused = paused;
}

void applied_input_flush(applied_input_t *ai) {
  if (!ai->open) return;
  ai->cur.tools._buffer = ai->tools;
  ai->cur.tools._maximum = ai->cur.tools._length;
  ai->cur.controls._buffer = ai->controls;
  ai->cur.controls._maximum = ai->cur.controls._length;
  ai->cur.seq = ++ai->seq;
  if (ai->outbox) {
    applied_outbox_push(ai->outbox, &ai->cur); /* a drop is counted there */
  } else if (ai->writer > 0) {
    if (dds_write(ai->writer, &ai->cur) >= 0)
      ai->published++;
    else
      ai->failed++;
  }
  ai->open = 0;
}

void applied_input_tick(applied_input_t *ai) {
  applied_input_flush(ai);
  ai->tick++;
}

/* Opens a sample with the state now, publishing the open one first when
 * the entry would not fit. */
static void need(applied_input_t *ai, int tool) {
  if (ai->open &&
      (tool ? ai->cur.tools._length >= APPLIED_MAX_TOOLS : ai->cur.controls._length >= APPLIED_MAX_CONTROLS))
    applied_input_flush(ai);
  if (ai->open) return;
  memset(&ai->cur, 0, sizeof ai->cur);
  ai->cur.tick = ai->tick;
  ai->cur.step = ai->rt->steps;
  ai->cur.sim_time_ns = (uint64_t)(ai->rt->sim_time * 1e9);
  ai->cur.epoch = ai->epoch;
  ai->cur.paused = ai->paused && *ai->paused;
  ai->open = 1;
}

void applied_input_command(applied_input_t *ai, size_t t, const tool_input_t *in) {
  need(ai, 1);
  viscera_AppliedTool *a = &ai->tools[ai->cur.tools._length++];
  memset(a, 0, sizeof *a);
  a->tool_id = (uint32_t)t;
  for (int k = 0; k < 3; k++) a->position[k] = in->pos[k];
  for (int k = 0; k < 4; k++) a->orientation[k] = in->q[k];
  a->buttons = in->buttons;
  a->max_force = in->max_force;
  a->cmd_seq = in->seq;
  a->cmd_client_mono_ns = in->echo;
}

void applied_input_release(applied_input_t *ai, size_t t) {
  need(ai, 1);
  viscera_AppliedTool *a = &ai->tools[ai->cur.tools._length++];
  memset(a, 0, sizeof *a);
  a->tool_id = (uint32_t)t;
  a->released = true;
}

void applied_input_begin_control(applied_input_t *ai) { need(ai, 0); }

void applied_input_control(applied_input_t *ai, const viscera_SessionControl *c, int result, int task) {
  if (!ai->open || ai->cur.controls._length >= APPLIED_MAX_CONTROLS) need(ai, 0); /* not begun: state now */
  viscera_AppliedControl *a = &ai->controls[ai->cur.controls._length++];
  memset(a, 0, sizeof *a);
  a->source_id = c->source_id;
  a->seq = c->seq;
  a->kind = c->kind;
  a->tool_id = c->tool_id;
  a->organ_id = c->organ_id;
  memcpy(a->values, c->values, sizeof a->values);
  memcpy(a->text, c->text, sizeof a->text);
  a->text[sizeof a->text - 1] = 0;
  a->result = result;
  a->task = task;
}

void applied_input_rebuilt(applied_input_t *ai) { ai->epoch++; }
