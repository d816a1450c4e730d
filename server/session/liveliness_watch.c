/* SPDX-License-Identifier: Apache-2.0 */
#include "session/liveliness_watch.h"

#include <string.h>

#include "vtime.h"

void liveliness_watch_init(liveliness_watch_t *w) {
  memset(w, 0, sizeof *w);
  pthread_mutex_init(&w->lock, NULL);
}

void liveliness_watch_destroy(liveliness_watch_t *w) { pthread_mutex_destroy(&w->lock); }

void liveliness_watch_note(liveliness_watch_t *w, const dds_liveliness_changed_status_t *st, uint64_t mono_ns) {
  pthread_mutex_lock(&w->lock);
  /* A writer going from alive to not-alive (lease expired) or deleted while
   * alive (alive_count drops with no not-alive rise): either way it no longer
   * drives its tool. last_publication_handle names the writer that changed. */
  if (st->alive_count_change < 0 || st->not_alive_count_change > 0) {
    if (st->alive_count_change < 0) {
      if (w->n == LIVELINESS_WATCH_CAP) {
        w->head = (w->head + 1) % LIVELINESS_WATCH_CAP;
        w->n--;
        w->dropped++;
      }
      liveliness_lost_t *e = &w->q[(w->head + w->n) % LIVELINESS_WATCH_CAP];
      e->writer = st->last_publication_handle;
      e->mono_ns = mono_ns;
      e->expired = st->not_alive_count_change > 0;
      e->regained = 0;
      w->n++;
      w->lost_total++;
    }
  } else if (st->alive_count_change > 0) {
    w->regained_total++;
    for (size_t i = 0; i < w->n; i++) {
      liveliness_lost_t *e = &w->q[(w->head + i) % LIVELINESS_WATCH_CAP];
      if (e->writer == st->last_publication_handle) e->regained = 1;
    }
  }
  pthread_mutex_unlock(&w->lock);
}

static void on_liveliness(dds_entity_t reader, const dds_liveliness_changed_status_t status, void *arg) {
  (void)reader;
  liveliness_watch_note(arg, &status, vtime_mono_ns());
}

void liveliness_watch_listen(liveliness_watch_t *w, dds_listener_t *l) {
  (void)w;
  dds_lset_liveliness_changed(l, on_liveliness);
}

int liveliness_watch_pop(liveliness_watch_t *w, uint64_t now, uint64_t confirm_ns, liveliness_lost_t *out) {
  pthread_mutex_lock(&w->lock);
  int got = w->n > 0 && now >= w->q[w->head].mono_ns + confirm_ns;
  if (got) {
    *out = w->q[w->head];
    w->head = (w->head + 1) % LIVELINESS_WATCH_CAP;
    w->n--;
  }
  pthread_mutex_unlock(&w->lock);
  return got;
}
