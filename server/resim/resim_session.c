/* SPDX-License-Identifier: Apache-2.0 */
#include "resim/resim_session.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "recording/rec_writers.h"

/* True when the comma-separated list `parts` names `p`. */
static bool lists(const char *parts, const char *p) {
  size_t lp = strlen(p);
  for (const char *s = parts; *s;) {
    const char *e = strchr(s, ',');
    size_t l = e ? (size_t)(e - s) : strlen(s);
    if (l == lp && !memcmp(s, p, l)) return true;
    if (!e) break;
    s = e + 1;
  }
  return false;
}

static int cmp_id(const void *a, const void *b) {
  int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
  return (x > y) - (x < y);
}

static int cmp_str(const void *a, const void *b) { return strcmp(*(const char *const *)a, *(const char *const *)b); }

/* The partitions of the SceneInfo writers (one per session), sorted, as
 * "a, b, c" (at most `cap` bytes, "..." when cut), and how many differ. */
static size_t sessions(const rec_writer_t *w, size_t n, int64_t scene_topic, char *names, size_t cap) {
  const char **p = malloc((n ? n : 1) * sizeof *p);
  size_t count = 0, used = 0;
  names[0] = 0;
  if (!p) return 0;
  for (size_t i = 0; i < n; i++) {
    if (w[i].topic_id != scene_topic) continue;
    bool seen = false;
    for (size_t j = 0; j < count && !seen; j++) seen = !strcmp(p[j], w[i].partitions);
    if (!seen) p[count++] = w[i].partitions;
  }
  qsort(p, count, sizeof *p, cmp_str);
  for (size_t i = 0; i < count; i++) {
    int k = snprintf(names + used, cap - used, "%s%s", used ? ", " : "", p[i][0] ? p[i] : "(no partition)");
    if (k < 0 || (size_t)k >= cap - used) {
      if (cap > 4) strcpy(names + cap - 4, "...");
      break;
    }
    used += (size_t)k;
  }
  free(p);
  return count;
}

/* Writers of one participant share the first 12 bytes of their GUIDs. */
#define PARTICIPANT_HEX 24

static bool same_participant(const char *a, const char *b) { return !strncmp(a, b, PARTICIPANT_HEX); }

int resim_session_pick(recfile_t *rf, const char *partition, size_t run, resim_session_t *out, verr_t *err) {
  memset(out, 0, sizeof *out);
  const recfile_topic_t *t = recfile_topic_by_name(rf, "viscera_SceneInfo");
  rec_writer_t *w = NULL;
  size_t n = 0;
  if (rec_writers_load(rf, &w, &n, err)) return -1;
  char names[200];
  size_t count = t ? sessions(w, n, t->id, names, sizeof names) : 0;
  bool whole = !partition || !*partition;
  if (whole && count > 1) {
    free(w);
    return verr_set(err, "the recording holds %zu sessions (partitions %s): choose one with --partition", count, names);
  }
  /* The server runs of the session: the owners of its SceneInfo writers,
   * in the order the recorder met them (writer ids grow). */
  const char **runs = malloc((n ? n : 1) * sizeof *runs);
  out->ids = malloc((n ? n : 1) * sizeof *out->ids);
  if (!runs || !out->ids) {
    free(runs);
    free(w);
    resim_session_free(out);
    return verr_set(err, "out of memory for %zu writers", n);
  }
  size_t nruns = 0;
  for (size_t i = 0; t && i < n; i++) {
    if (w[i].topic_id != t->id || (!whole && !lists(w[i].partitions, partition))) continue;
    bool seen = false;
    for (size_t j = 0; j < nruns && !seen; j++) seen = same_participant(runs[j], w[i].guid);
    if (!seen) runs[nruns++] = w[i].guid;
  }
  int rc = 0;
  if (!whole && !nruns)
    rc = verr_set(err, "no session in partition '%.100s' (the recording's: %s)", partition, count ? names : "none");
  else if (run > nruns)
    rc = verr_set(err, "--run %zu: the session holds %zu run(s) of its server", run, nruns);
  if (rc || (whole && nruns <= 1)) { /* an error, or one session of one run: every sample */
    free(runs);
    free(w);
    if (rc)
      resim_session_free(out);
    else {
      free(out->ids);
      out->ids = NULL;
      out->nruns = nruns;
    }
    return rc;
  }
  size_t keep = run ? run - 1 : nruns - 1;
  for (size_t i = 0; i < n; i++) {
    if (!whole && !lists(w[i].partitions, partition)) continue;
    bool other = false;
    for (size_t j = 0; j < nruns && !other; j++) other = j != keep && same_participant(runs[j], w[i].guid);
    if (!other) out->ids[out->n++] = w[i].id;
  }
  free(runs);
  free(w);
  qsort(out->ids, out->n, sizeof *out->ids, cmp_id);
  out->filter = true;
  out->nruns = nruns;
  out->run = nruns > 1 ? keep + 1 : 0;
  if (!whole) snprintf(out->partition, sizeof out->partition, "%s", partition);
  return 0;
}

bool resim_session_has(const resim_session_t *s, int64_t writer_id) {
  if (!s->filter) return true;
  return bsearch(&writer_id, s->ids, s->n, sizeof *s->ids, cmp_id) != NULL;
}

void resim_session_free(resim_session_t *s) {
  free(s->ids);
  memset(s, 0, sizeof *s);
}
