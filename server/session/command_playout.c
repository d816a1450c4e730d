/* SPDX-License-Identifier: Apache-2.0 */
#include "session/command_playout.h"

#include <string.h>

/* Drops the oldest waiting command. */
static void drop_oldest(command_playout_t *p) {
  memmove(&p->wait[0], &p->wait[1], (p->n - 1) * sizeof p->wait[0]);
  p->n--;
  if (p->carried) p->carried--;
}

void command_playout_push(command_playout_t *p, size_t depth, const tool_input_t *c) {
  if (depth > PLAYOUT_MAX_DEPTH) depth = PLAYOUT_MAX_DEPTH;
  if (p->n == depth + 1) {
    drop_oldest(p);
    p->superseded++;
  }
  p->wait[p->n++] = *c;
}

int command_playout_next(command_playout_t *p, tool_input_t *out) {
  if (!p->n) {
    p->waited_steps = 0;
    return 0;
  }
  if (p->waited_steps >= PLAYOUT_CATCHUP_STEPS && p->n >= 2) {
    drop_oldest(p);
    p->caught_up++;
    p->waited_steps = 0;
  }
  if (p->carried) p->delayed++;
  *out = p->wait[0];
  drop_oldest(p);
  p->carried = p->n;
  p->waited_steps = p->n ? p->waited_steps + 1 : 0;
  return 1;
}

void command_playout_clear(command_playout_t *p) {
  p->n = 0;
  p->carried = 0;
  p->waited_steps = 0;
}
