/* SPDX-License-Identifier: Apache-2.0 */
#include "recording/rec_writers.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include <sqlite3.h>

#include "dds/vdds_ident.h"

static void copy_clean(char *dst, size_t size, sqlite3_stmt *st, int col) {
  const void *t = sqlite3_column_blob(st, col);
  vdds_ident_sanitize(dst, size, t, t ? (size_t)sqlite3_column_bytes(st, col) : 0);
}

typedef struct pp_list {
  recfile_participant_t *p;
  size_t n, cap;
  bool oom;
} pp_list_t;

static void on_participant(void *arg, const recfile_participant_t *p) {
  pp_list_t *l = arg;
  if (l->n == l->cap) {
    size_t nc = l->cap ? 2 * l->cap : 16;
    recfile_participant_t *np = realloc(l->p, nc * sizeof *np);
    if (!np) {
      l->oom = true;
      return;
    }
    l->p = np, l->cap = nc;
  }
  l->p[l->n++] = *p;
}

int rec_writers_load(recfile_t *rf, rec_writer_t **out, size_t *n, verr_t *err) {
  *out = NULL;
  *n = 0;
  sqlite3 *db = recfile_sqlite(rf);
  sqlite3_stmt *st = NULL;
  if (sqlite3_prepare_v2(db, "SELECT id, topic_id, guid, partitions FROM writers ORDER BY id", -1, &st, NULL) !=
      SQLITE_OK) {
    sqlite3_finalize(st);
    return verr_set(err, "%s: writers table unreadable: %s", recfile_path(rf), sqlite3_errmsg(db));
  }
  pp_list_t pl = {0};
  recfile_participants(rf, on_participant, &pl); /* optional table */
  rec_writer_t *w = NULL;
  size_t cap = 0;
  int rc;
  while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
    if (*n == cap) {
      size_t nc = cap ? 2 * cap : 32;
      rec_writer_t *nw = realloc(w, nc * sizeof *nw);
      if (!nw) break;
      w = nw, cap = nc;
    }
    rec_writer_t *x = &w[(*n)++];
    memset(x, 0, sizeof *x);
    x->id = sqlite3_column_int64(st, 0);
    x->topic_id = sqlite3_column_int64(st, 1);
    copy_clean(x->guid, sizeof x->guid, st, 2);
    copy_clean(x->partitions, sizeof x->partitions, st, 3);
    /* A writer's GUID shares its first 12 bytes (24 hex digits) with its
     * participant's. */
    for (size_t k = 0; k < pl.n; k++)
      if (strlen(x->guid) == 32 && strncmp(pl.p[k].guid, x->guid, 24) == 0) {
        snprintf(x->participant, sizeof x->participant, "%s", pl.p[k].user_data);
        snprintf(x->subject, sizeof x->subject, "%s", pl.p[k].subject);
        snprintf(x->role, sizeof x->role, "%s", pl.p[k].role);
        break;
      }
  }
  bool done = rc == SQLITE_DONE;
  const char *msg = sqlite3_errmsg(db);
  sqlite3_finalize(st);
  free(pl.p);
  *out = w;
  if (!done) return verr_set(err, "%s: writers table: %s", recfile_path(rf), msg ? msg : "read failed");
  return 0;
}

const rec_writer_t *rec_writer_find(const rec_writer_t *w, size_t n, int64_t id) {
  size_t lo = 0, hi = n;
  while (lo < hi) {
    size_t mid = lo + (hi - lo) / 2;
    if (w[mid].id < id)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo < n && w[lo].id == id ? &w[lo] : NULL;
}

bool rec_ident_field(const char *user_data, const char *key, char *out, size_t size) {
  size_t kl = strlen(key);
  for (const char *p = user_data; p && *p; p = strchr(p, ' '), p = p ? p + 1 : NULL) {
    if (strncmp(p, key, kl) == 0 && p[kl] == '=') {
      const char *v = p + kl + 1;
      size_t len = strcspn(v, " ");
      if (len >= size) len = size - 1;
      memcpy(out, v, len);
      out[len] = 0;
      return true;
    }
  }
  return false;
}
