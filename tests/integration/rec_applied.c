/* SPDX-License-Identifier: Apache-2.0 */
/* rec_applied: reads a session recording's AppliedInput samples (issue 16,
 * rec_read.h) and prints, per sample that acted on a SessionControl:
 *   CONTROL row=ID tick=N step=K epoch=E kind=C result=R task=T
 * then one line `ROWS id,id,...` with the row ids of those samples (what a
 * test deletes to take the controls out of a copy). Exit 1 when the file
 * cannot be read or a sample does not decode.
 * usage: rec_applied FILE.db */
#include <inttypes.h>
#include <stdio.h>

#include "rec_read.h"
#include "viscera.h"

typedef struct rows {
  int n;
} rows_t;

static int on_applied(void *arg, const void *sample, const recfile_row_t *row) {
  rows_t *r = arg;
  const viscera_AppliedInput *a = sample;
  for (uint32_t i = 0; i < a->controls._length; i++) {
    const viscera_AppliedControl *c = &a->controls._buffer[i];
    printf("CONTROL row=%lld tick=%" PRIu64 " step=%" PRIu64 " epoch=%u kind=%d result=%d task=%d\n",
           (long long)row->id, a->tick, a->step, a->epoch, (int)c->kind, (int)c->result, (int)c->task);
  }
  if (a->controls._length) {
    fprintf(stderr, "%s%lld", r->n++ ? "," : "ROWS ", (long long)row->id);
  }
  return 0;
}

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: rec_applied FILE.db\n");
    return 2;
  }
  recfile_t *rf = NULL;
  verr_t err;
  if (recfile_open(&rf, argv[1], &err) < 0) {
    fprintf(stderr, "rec_applied: %s\n", err.msg);
    return 1;
  }
  rows_t r = {0};
  int bad = rec_read_topic("rec_applied", rf, "viscera_AppliedInput", &viscera_AppliedInput_desc, on_applied, &r);
  if (r.n) fprintf(stderr, "\n");
  recfile_close(rf);
  return bad ? 1 : 0;
}
