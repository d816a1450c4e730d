/* SPDX-License-Identifier: Apache-2.0 */
/* rec_feedback_first: reads a session recording (rec_read.h) and judges,
 * from the server's own records, when each tool command was answered
 * (issue 17 item 5: feedback before the tissue step).
 *
 * AppliedInput says which command each tool took before which step (its
 * sim_time_ns is the simulated time at the start of that step). The first
 * ContactFeedback echoing that command (its cmd_seq, lowest
 * ContactFeedback.seq) must carry that start time: it was written before
 * the step's tissue step. Written after the step (the old order) it would
 * carry the start time + dt ("late"). Per tool the feedback samples, each
 * placed on the step it answers (an answer before the step: start / dt; any
 * other: end / dt - 1), must fall on strictly increasing steps: never two
 * in one step.
 *
 * A command that moved the tool's tip further than the server's jump
 * (server/session/session_tool.h: SESSION_EARLY_JUMP_M, 0.25 mm, from the
 * position AppliedInput gave the tool before) is answered after the step
 * instead (issue 14: an answer before the tissue yields to a jump stretches
 * the tool's spring by all of it): a jump above twice that must be answered
 * late ("jump_late"; answered before the step it is "jump_early", a
 * failure), a move below half of it on time, one in between either way
 * (answered late it counts as "edge").
 *
 * Prints `FEEDBACK_FIRST commands=N answered=A on_time=O late=L other=X
 * repeated=R jump_late=J jump_early=E edge=G dt_ns=D` and exits 0 when late =
 * other = repeated = jump_early = 0, at least `min` commands were answered
 * (missing samples of a best-effort topic are not a failure) and at least
 * `min_jumps` jumps were answered late; 1 otherwise or when the recording
 * cannot be read. usage: rec_feedback_first FILE.db MIN [MIN_JUMPS] */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "rec_read.h"
#include "rec_taken.h"
#include "viscera.h"

#define MAXT REC_TAKEN_TOOLS
#define JUMP_M 2.5e-4 /* = SESSION_EARLY_JUMP_M (server/session/session_tool.h) */

typedef struct fb {
  uint64_t seq, cmd_seq, sim_ns;
} fb_t;

typedef struct data {
  rec_taken_t taken; /* the commands each tool took, the step each was taken in (rec_taken.h) */
  fb_t *fb[MAXT];
  size_t nfb[MAXT], capf[MAXT];
  int oom;
} data_t;

static void *grow(void *p, size_t *cap, size_t n, size_t size, int *oom) {
  if (n < *cap) return p;
  size_t c = *cap ? 2 * *cap : 1024;
  void *q = realloc(p, c * size);
  if (!q) {
    *oom = 1;
    return NULL;
  }
  *cap = c;
  return q;
}

static int on_feedback(void *arg, const void *sample, const recfile_row_t *row) {
  (void)row;
  data_t *d = arg;
  const viscera_ContactFeedback *f = sample;
  if (f->tool_id >= MAXT) return 0;
  size_t k = f->tool_id;
  fb_t *b = grow(d->fb[k], &d->capf[k], d->nfb[k], sizeof *b, &d->oom);
  if (!b) return 0;
  d->fb[k] = b;
  b[d->nfb[k]++] = (fb_t){f->seq, f->cmd_seq, f->sim_time_ns};
  return 0;
}

static int by_seq(const void *a, const void *b) {
  uint64_t x = ((const fb_t *)a)->seq, y = ((const fb_t *)b)->seq;
  return x < y ? -1 : x > y;
}

int main(int argc, char **argv) {
  if (argc != 3 && argc != 4) {
    fprintf(stderr, "usage: rec_feedback_first FILE.db MIN [MIN_JUMPS]\n");
    return 2;
  }
  recfile_t *rf = NULL;
  verr_t err;
  if (recfile_open(&rf, argv[1], &err) < 0) {
    fprintf(stderr, "rec_feedback_first: %s\n", err.msg);
    return 1;
  }
  static data_t d;
  int bad = rec_taken_read("rec_feedback_first", rf, &d.taken);
  bad += rec_read_topic("rec_feedback_first", rf, "viscera_ContactFeedback", &viscera_ContactFeedback_desc, on_feedback,
                        &d);
  recfile_close(rf);
  const uint64_t dt_ns = d.taken.dt_ns;
  if (bad || d.oom || d.taken.oom || !dt_ns) {
    fprintf(stderr, "rec_feedback_first: %s\n",
            d.oom || d.taken.oom ? "out of memory"
            : bad                ? "unreadable samples"
                                 : "no step seen");
    return 1;
  }
  size_t commands = 0, answered = 0, on_time = 0, late = 0, other = 0, repeated = 0, jump_late = 0, jump_early = 0,
         edge = 0;
  for (size_t t = 0; t < MAXT; t++) {
    if (d.nfb[t]) qsort(d.fb[t], d.nfb[t], sizeof *d.fb[t], by_seq); /* (a tool without samples has no array) */
    /* The step each sample answers: before the step it took a command in,
     * after the step otherwise. `early[i]` marks the first answers. */
    char *early = calloc(d.nfb[t] + 1, 1);
    if (!early) return 1;
    size_t j = 0;
    for (size_t i = 0; i < d.taken.n[t]; i++) {
      const rec_taken_cmd_t *c = &d.taken.cmd[t][i];
      commands++;
      /* Commands and answers go in the same order: the first sample at or
       * after j echoing this seq. */
      size_t f = j;
      while (f < d.nfb[t] && d.fb[t][f].cmd_seq != c->seq) f++;
      if (f == d.nfb[t]) continue; /* not recorded (best effort) */
      j = f + 1;
      answered++;
      int jump = c->move > 2 * JUMP_M, either = !jump && c->move >= 0.5 * JUMP_M;
      if (d.fb[t][f].sim_ns == c->start_ns) {
        if (jump) {
          jump_early++;
          if (jump_early <= 5)
            fprintf(stderr, "tool %zu command %" PRIu64 " moved the tip %.3f mm and was answered before the step\n", t,
                    c->seq, c->move * 1e3);
        } else {
          on_time++;
        }
        early[f] = 1;
      } else if (llabs((int64_t)(d.fb[t][f].sim_ns - c->start_ns) - (int64_t)dt_ns) <= 1) { /* ns truncation */
        if (jump)
          jump_late++;
        else if (either)
          edge++; /* near the server's jump: either way is right */
        else
          late++;
      } else {
        other++;
        if (other <= 5)
          fprintf(stderr, "tool %zu command %" PRIu64 " taken at %" PRIu64 " ns first answered at %" PRIu64 " ns\n", t,
                  c->seq, c->start_ns, d.fb[t][f].sim_ns);
      }
    }
    int64_t last = -1;
    for (size_t i = 0; i < d.nfb[t]; i++) {
      int64_t step = (int64_t)llround((double)d.fb[t][i].sim_ns / (double)dt_ns) - (early[i] ? 0 : 1);
      if (step <= last) repeated++;
      last = step;
    }
    free(early);
    free(d.fb[t]);
  }
  rec_taken_free(&d.taken);
  long min = strtol(argv[2], NULL, 10), min_jumps = argc == 4 ? strtol(argv[3], NULL, 10) : 0;
  printf("FEEDBACK_FIRST commands=%zu answered=%zu on_time=%zu late=%zu other=%zu repeated=%zu jump_late=%zu "
         "jump_early=%zu edge=%zu dt_ns=%" PRIu64 "\n",
         commands, answered, on_time, late, other, repeated, jump_late, jump_early, edge, dt_ns);
  return late == 0 && other == 0 && repeated == 0 && jump_early == 0 && (long)answered >= min &&
                 (long)jump_late >= min_jumps
             ? 0
             : 1;
}
