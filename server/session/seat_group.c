/* SPDX-License-Identifier: Apache-2.0 */
#include "session/seat_group.h"

#include <stdio.h>
#include <stdlib.h>

#include "vtime.h"

/* Steps the open sessions s[k] (NULL: not open; at least one open) on the
 * calling thread until *stop or o's duration (seat_group.h). */
static void step_loop(server_t **s, int n, const server_opts_t *o, volatile sig_atomic_t *stop) {
  server_thread_prepare(o, o->log_tag ? o->log_tag : "server");
  /* Stepping: s[k] != NULL and live[k]. */
  unsigned char *live = calloc((size_t)n, 1);
  if (!live) return;
  int open = 0;
  uint64_t dt_ns = 0;
  for (int k = 0; k < n; k++)
    if ((live[k] = s[k] != NULL)) {
      open++;
      if (!dt_ns) dt_ns = server_dt_ns(s[k]);
    }
  uint64_t start = vtime_mono_ns(), next = start, tick = 0;
  while (open && !*stop && (o->duration <= 0 || (double)(vtime_mono_ns() - start) * 1e-9 < o->duration)) {
    uint64_t t0 = vtime_mono_ns(), t1 = t0;
    /* The tick's first seat finds the core as the sleep left it (other
     * processes ran): the order turns every tick so no seat always
     * pays for that, nor always answers last. */
    const int first = (int)(tick++ % (uint64_t)n);
    for (int i = 0; i < n; i++) {
      int k = (first + i) % n;
      if (live[k] && server_step_begin(s[k], t0)) {
        server_note_overrun(s[k]);
        live[k] = 0; /* its scene could not be rebuilt: nothing left to simulate */
        open--;
      }
    }
    for (int i = 0; i < n; i++)
      if (live[(first + i) % n]) server_step_tissue(s[(first + i) % n]);
    for (int i = 0; i < n; i++)
      if (live[(first + i) % n]) t1 = server_step_end(s[(first + i) % n]);
    next += dt_ns;
    if (t1 > next + SERVER_RESYNC_NS) { /* far behind (debugger, overload): resynchronise */
      for (int k = 0; k < n; k++)
        if (live[k]) server_note_overrun(s[k]);
      next = t1;
    }
    vtime_sleep_until(next);
  }
  free(live);
}

void seat_group_run(seat_group_member_t *m, int n, volatile sig_atomic_t *stop) {
  server_t **s = calloc((size_t)n, sizeof *s);
  if (!s) {
    for (int k = 0; k < n; k++) {
      m[k].rc = 1;
      verr_set(&m[k].err, "out of memory for its group");
      fprintf(stderr, "viscera-server: seat '%s': %s\n", m[k].name, m[k].err.msg);
    }
    return;
  }
  int open = 0;
  for (int k = 0; k < n; k++) {
    m[k].rc = 0;
    if (!(s[k] = server_open(m[k].scene, m[k].opts, m[k].stats, &m[k].err))) {
      m[k].rc = 1;
      fprintf(stderr, "viscera-server: seat '%s': %s\n", m[k].name, m[k].err.msg);
    } else
      open++;
  }
  if (open) step_loop(s, n, m[0].opts, stop);
  for (int k = 0; k < n; k++)
    if (s[k]) server_close(s[k]);
  free(s);
}

int server_run(const scene_t *scene, const server_opts_t *opts, volatile sig_atomic_t *stop, server_stats_t *stats,
               verr_t *err) {
  server_t *s = server_open(scene, opts, stats, err);
  if (!s) return -1;
  step_loop(&s, 1, opts, stop);
  server_close(s);
  return 0;
}
