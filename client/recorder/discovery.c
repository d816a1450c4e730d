/* SPDX-License-Identifier: Apache-2.0 */
#include "discovery.h"

#include <fnmatch.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct discovery {
  dds_entity_t reader;
  char *pattern;
};

int discovery_open(discovery_t **out, dds_entity_t participant, const char *pattern, verr_t *err) {
  *out = NULL;
  discovery_t *d = calloc(1, sizeof *d);
  if (!d || !(d->pattern = strdup(pattern))) {
    free(d);
    return verr_set(err, "discovery: out of memory");
  }
  /* The built-in reader is transient-local in effect: writers that existed
   * before the recorder started are reported on the first take. */
  d->reader = dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, NULL, NULL);
  if (d->reader < 0) {
    verr_set(err, "DDS: cannot read DCPSPublication: %s", dds_strretcode(d->reader));
    free(d->pattern);
    free(d);
    return -1;
  }
  *out = d;
  return 0;
}

void discovery_close(discovery_t *d) {
  if (!d) return;
  dds_delete(d->reader);
  free(d->pattern);
  free(d);
}

dds_entity_t discovery_reader(const discovery_t *d) { return d->reader; }

bool discovery_partition_matches(const char *pattern, const dds_qos_t *qos, char *joined, size_t size) {
  uint32_t n = 0;
  char **ps = NULL;
  bool match = false;
  size_t len = 0;
  if (joined && size) joined[0] = 0;
  if (!qos || !dds_qget_partition(qos, &n, &ps) || n == 0) {
    /* No partition QoS means the default partition, named "". */
    dds_free(ps);
    return fnmatch(pattern, "", 0) == 0;
  }
  for (uint32_t i = 0; i < n; i++) {
    if (fnmatch(pattern, ps[i], 0) == 0) match = true;
    if (joined && len + 1 < size) len += (size_t)snprintf(joined + len, size - len, "%s%s", i ? "," : "", ps[i]);
    dds_free(ps[i]);
  }
  dds_free(ps);
  return match;
}

int discovery_poll(discovery_t *d, discovery_cb cb, void *arg) {
  enum { N = 32 };
  void *ptrs[N];
  dds_sample_info_t si[N];
  int reported = 0;
  for (;;) {
    ptrs[0] = NULL; /* loan */
    dds_return_t n = dds_take(d->reader, ptrs, si, N, N);
    if (n < 0) return n;
    if (n == 0) break;
    for (int i = 0; i < n; i++) {
      /* A writer that left is NOT_ALIVE; its samples already recorded stay
       * attributed to it, nothing else to do. */
      if (!si[i].valid_data || si[i].instance_state != DDS_IST_ALIVE) continue;
      const dds_builtintopic_endpoint_t *ep = ptrs[i];
      char parts[512];
      if (!ep->topic_name || !ep->type_name) continue;
      if (!discovery_partition_matches(d->pattern, ep->qos, parts, sizeof parts)) continue;
      disc_writer_t w = {ep->key, ep->topic_name, ep->type_name, ep->qos, parts};
      cb(arg, &w);
      reported++;
    }
    dds_return_loan(d->reader, ptrs, n);
    if (n < N) break;
  }
  return reported;
}

disc_writer_t *disc_writer_dup(const disc_writer_t *w) {
  disc_writer_t *c = calloc(1, sizeof *c);
  if (!c) return NULL;
  c->guid = w->guid;
  c->topic_name = strdup(w->topic_name);
  c->type_name = strdup(w->type_name);
  c->partitions = strdup(w->partitions ? w->partitions : "");
  dds_qos_t *q = dds_create_qos();
  if (q && w->qos) dds_copy_qos(q, w->qos);
  c->qos = q;
  if (!c->topic_name || !c->type_name || !c->partitions || !c->qos) {
    disc_writer_free(c);
    return NULL;
  }
  return c;
}

void disc_writer_free(disc_writer_t *w) {
  if (!w) return;
  free((char *)w->topic_name);
  free((char *)w->type_name);
  free((char *)w->partitions);
  if (w->qos) dds_delete_qos((dds_qos_t *)w->qos);
  free(w);
}
