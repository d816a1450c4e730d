/* SPDX-License-Identifier: Apache-2.0 */
#include "resim/resim_schedule.h"

#include <stdlib.h>

/* Feedback by step; for one step the later-written sample last, so that
 * "the later wins" on a conflict. */
static int cmp_fb(const void *a, const void *b) {
  const resim_fb_t *x = a, *y = b;
  if (x->step != y->step) return x->step < y->step ? -1 : 1;
  if (x->wall_ns != y->wall_ns) return x->wall_ns < y->wall_ns ? -1 : 1;
  return x->seq < y->seq ? -1 : x->seq > y->seq;
}

static int cmp_cmd(const void *a, const void *b) {
  const resim_cmd_t *x = a, *y = b;
  return x->seq < y->seq ? -1 : x->seq > y->seq;
}

static int cmp_u64(const void *a, const void *b) {
  uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return x < y ? -1 : x > y;
}

/* Index of the first command with seq >= want (ncmd if none). */
static size_t lower_bound(const resim_cmd_t *c, size_t n, uint64_t want) {
  size_t lo = 0, hi = n;
  while (lo < hi) {
    size_t mid = lo + (hi - lo) / 2;
    if (c[mid].seq < want)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

/* The recorded command with this seq, else the nearest below (above if
 * none below); *missing set when it was not recorded. ncmd > 0. */
static int32_t find_cmd(const resim_tool_input_t *in, uint64_t seq, int *missing) {
  size_t i = lower_bound(in->cmd, in->ncmd, seq);
  *missing = !(i < in->ncmd && in->cmd[i].seq == seq);
  if (*missing) i = i > 0 ? i - 1 : 0;
  return (int32_t)i;
}

int resim_schedule_build(resim_tool_input_t *in, uint64_t nsteps, int32_t *out, resim_schedule_stats_t *st,
                         verr_t *err) {
  for (uint64_t k = 0; k <= nsteps; k++) out[k] = -1;
  if (in->nfb == 0) return 0;
  if (in->ncmd == 0)
    return verr_set(err, "%zu ContactFeedback samples name commands, but no ToolCommand of the tool was recorded",
                    in->nfb);
  qsort(in->fb, in->nfb, sizeof *in->fb, cmp_fb);
  qsort(in->cmd, in->ncmd, sizeof *in->cmd, cmp_cmd);
  if (in->nrelease) qsort(in->release, in->nrelease, sizeof *in->release, cmp_u64);

  /* One sample per step (step 0 precedes any command: impossible, dropped). */
  size_t n = 0;
  for (size_t i = 0; i < in->nfb; i++) {
    if (in->fb[i].step == 0 || in->fb[i].step > nsteps) continue;
    if (n > 0 && in->fb[n - 1].step == in->fb[i].step) {
      if (in->fb[n - 1].seq != in->fb[i].seq) st->conflicts++;
      in->fb[n - 1] = in->fb[i];
    } else {
      in->fb[n++] = in->fb[i];
    }
  }

  size_t r = 0;
  uint64_t last_missing_seq = UINT64_MAX;
  for (size_t i = 0; i < n; i++) {
    const resim_fb_t *f = &in->fb[i];
    uint64_t k1 = f->step;
    int missing;
    int32_t c1 = find_cmd(in, f->seq, &missing);
    if (missing && f->seq != last_missing_seq) {
      st->missing_commands++;
      last_missing_seq = f->seq;
    }
    out[k1] = c1;
    st->feedback_steps++;
    int last = i + 1 == n;
    uint64_t k2 = last ? nsteps + 1 : in->fb[i + 1].step; /* next known step */
    if (k2 == k1 + 1) continue;

    while (r < in->nrelease && in->release[r] < k1) r++;
    if (r < in->nrelease && in->release[r] < k2) {
      /* Released before step e + 1: the tool was silent, so c1 held until then. */
      uint64_t e = in->release[r];
      for (uint64_t k = k1 + 1; k <= e && k < k2; k++) out[k] = c1;
      if (e > k1) st->bridged_steps += e - k1;
      st->releases++;
      while (r < in->nrelease && in->release[r] < k2) r++;
      continue;
    }
    if (last) {
      /* The recording ends here (the recorder stops before the server):
       * hold the command; no frame after the recorder stopped is compared. */
      for (uint64_t k = k1 + 1; k <= nsteps; k++) out[k] = c1;
      continue;
    }
    const resim_fb_t *g = &in->fb[i + 1];
    st->gaps++;
    if (g->seq == f->seq) {
      for (uint64_t k = k1 + 1; k < k2; k++) out[k] = c1;
      st->bridged_steps += k2 - k1 - 1;
      continue;
    }
    /* Ambiguous: a newer command arrived somewhere in the gap. Commands with
     * seq in (s1, s2] are the candidates, in seq order. */
    st->ambiguous_steps += k2 - k1 - 1;
    size_t j0 = lower_bound(in->cmd, in->ncmd, f->seq + 1), j1 = lower_bound(in->cmd, in->ncmd, g->seq + 1);
    int timed = f->wall_ns > 0 && g->wall_ns > f->wall_ns;
    int32_t cur = c1;
    size_t j = j0;
    for (uint64_t k = k1 + 1; k < k2; k++) {
      if (timed) {
        /* The step's feedback would have been written about here. */
        double a = (double)(k - k1) / (double)(k2 - k1);
        int64_t t = f->wall_ns + (int64_t)(a * (double)(g->wall_ns - f->wall_ns));
        while (j < j1 && in->cmd[j].wall_ns > 0 && in->cmd[j].wall_ns <= t) cur = (int32_t)j++;
      }
      out[k] = cur;
    }
  }
  return 0;
}
