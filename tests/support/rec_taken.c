/* SPDX-License-Identifier: Apache-2.0 */
#include "rec_taken.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rec_read.h"
#include "viscera.h"

static int on_applied(void *arg, const void *sample, const recfile_row_t *row) {
  (void)row;
  rec_taken_t *d = arg;
  const viscera_AppliedInput *a = sample;
  if (a->step > 0 && !d->dt_ns) d->dt_ns = (uint64_t)llround((double)a->sim_time_ns / (double)a->step);
  if (a->paused) return 0; /* a paused session takes no step */
  for (uint32_t i = 0; i < a->tools._length; i++) {
    const viscera_AppliedTool *t = &a->tools._buffer[i];
    if (t->tool_id >= REC_TAKEN_TOOLS) continue;
    size_t k = t->tool_id;
    if (t->released) { /* the next command is a new start, not a move */
      d->has_prev[k] = 0;
      continue;
    }
    double move = 0;
    if (d->has_prev[k])
      move = sqrt(pow(t->position[0] - d->prev[k][0], 2) + pow(t->position[1] - d->prev[k][1], 2) +
                  pow(t->position[2] - d->prev[k][2], 2));
    for (int q = 0; q < 3; q++) d->prev[k][q] = t->position[q];
    d->has_prev[k] = 1;
    if (d->n[k] == d->cap[k]) {
      size_t cap = d->cap[k] ? 2 * d->cap[k] : 1024;
      rec_taken_cmd_t *c = realloc(d->cmd[k], cap * sizeof *c);
      if (!c) {
        d->oom = 1;
        return 1; /* stop reading */
      }
      d->cmd[k] = c;
      d->cap[k] = cap;
    }
    d->cmd[k][d->n[k]++] = (rec_taken_cmd_t){t->cmd_seq, a->sim_time_ns, move};
  }
  return 0;
}

int rec_taken_read(const char *tool, recfile_t *rf, rec_taken_t *t) {
  memset(t, 0, sizeof *t);
  int bad = rec_read_topic(tool, rf, "viscera_AppliedInput", &viscera_AppliedInput_desc, on_applied, t);
  return bad + t->oom;
}

int rec_taken_in(rec_taken_t *t, unsigned tool, uint64_t seq, uint64_t start_ns) {
  if (tool >= REC_TAKEN_TOOLS) return 0;
  for (size_t c = t->cursor[tool]; c < t->n[tool]; c++)
    if (t->cmd[tool][c].seq == seq) {
      t->cursor[tool] = c;
      return t->cmd[tool][c].start_ns == start_ns;
    }
  return 0;
}

void rec_taken_free(rec_taken_t *t) {
  for (int k = 0; k < REC_TAKEN_TOOLS; k++) free(t->cmd[k]);
  memset(t, 0, sizeof *t);
}
