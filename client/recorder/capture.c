/* SPDX-License-Identifier: Apache-2.0 */
#include "capture.h"

#include <stdlib.h>
#include <string.h>

#include <dds/ddsi/ddsi_serdata.h>

#include "discovery.h"
#include "handle_set.h"
#include "recording/recording.h"
#include "vtime.h"

/* Samples per dds_takecdr: big enough to amortise the call, small enough
 * that the per-take sort and the serdata references stay cheap. */
#define CHUNK 256

typedef struct cap_writer {
  uint8_t guid[16];
  dds_instance_handle_t handle; /* publication handle, 0 until seen */
  int64_t id;
} cap_writer_t;

/* One row to store: a taken sample, or an inferred dispose/unregister
 * after it (same serdata). */
typedef struct cap_entry {
  int64_t ts;
  uint32_t seq; /* tie-break: take order, inferred rows right after their sample */
  uint16_t idx;
  uint8_t kind;
  uint8_t inferred;
} cap_entry_t;

struct capture {
  char *topic_name;
  char *type_name;
  dds_entity_t topic;
  dds_entity_t reader;
  int64_t topic_id;
  dds_reliability_kind_t reliability;
  dds_durability_kind_t durability;
  dds_ownership_kind_t ownership;
  cap_writer_t *writers;
  size_t nwriters, capwriters;
  /* Handles no writer could be found for (already gone): asked once. */
  handle_set_t unknown_handles;
  /* Instances whose dispose/unregister this drain already stored. */
  handle_set_t ended;
  unsigned char *buf;
  size_t bufcap;
  struct ddsi_serdata *sd[CHUNK];
  dds_sample_info_t si[CHUNK];
  cap_entry_t entries[2 * CHUNK];
};

static dds_qos_t *reader_qos_for(const dds_qos_t *wq, int32_t depth) {
  dds_qos_t *q = dds_create_qos();
  if (!q) return NULL;
  /* DDS's default writer reliability is reliable (100 ms blocking). */
  dds_reliability_kind_t rel = DDS_RELIABILITY_RELIABLE;
  dds_duration_t blocking = DDS_MSECS(100);
  if (wq) dds_qget_reliability(wq, &rel, &blocking);
  dds_qset_reliability(q, rel, blocking);
  dds_durability_kind_t dur = DDS_DURABILITY_VOLATILE;
  if (wq) dds_qget_durability(wq, &dur);
  if (dur > DDS_DURABILITY_TRANSIENT_LOCAL) dur = DDS_DURABILITY_TRANSIENT_LOCAL;
  dds_qset_durability(q, dur);
  /* Keep-last, not keep-all: a keep-all reliable reader would push back on
   * the writer, and a recorder must never slow the physics or the 1 kHz
   * haptic loop. A deep history absorbs stalls of the recorder instead. */
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
  dds_ownership_kind_t own;
  if (wq && dds_qget_ownership(wq, &own)) dds_qset_ownership(q, own);
  dds_duration_t lb;
  if (wq && dds_qget_latency_budget(wq, &lb)) dds_qset_latency_budget(q, lb);
  uint32_t nrep = 0;
  dds_data_representation_id_t *reps = NULL;
  if (wq && dds_qget_data_representation(wq, &nrep, &reps) && nrep > 0) dds_qset_data_representation(q, nrep, reps);
  dds_free(reps);
  return q;
}

int capture_create(capture_t **out, dds_entity_t participant, dds_entity_t subscriber, const char *topic_name,
                   const dds_topic_descriptor_t *desc, const dds_qos_t *writer_qos, int32_t depth, store_t *store,
                   verr_t *err) {
  *out = NULL;
  capture_t *c = calloc(1, sizeof *c);
  if (!c) return verr_set(err, "out of memory");
  c->unknown_handles = HANDLE_SET_INIT;
  c->ended = HANDLE_SET_INIT;
  if (!(c->topic_name = strdup(topic_name)) || !(c->type_name = strdup(desc->m_typename))) {
    verr_set(err, "out of memory");
    goto fail;
  }
  c->topic = dds_create_topic(participant, desc, topic_name, NULL, NULL);
  if (c->topic < 0) {
    verr_set(err, "DDS: cannot create topic '%s' from the discovered type: %s", topic_name, dds_strretcode(c->topic));
    goto fail;
  }
  dds_qos_t *rq = reader_qos_for(writer_qos, depth > 0 ? depth : CAPTURE_DEFAULT_DEPTH);
  if (!rq) {
    verr_set(err, "out of memory");
    goto fail;
  }
  dds_qget_reliability(rq, &c->reliability, &(dds_duration_t){0});
  dds_qget_durability(rq, &c->durability);
  if (!dds_qget_ownership(rq, &c->ownership)) c->ownership = DDS_OWNERSHIP_SHARED;
  c->reader = dds_create_reader(subscriber, c->topic, rq, NULL);
  dds_delete_qos(rq);
  if (c->reader < 0) {
    verr_set(err, "DDS: cannot create reader for '%s': %s", topic_name, dds_strretcode(c->reader));
    goto fail;
  }
  if (store_add_topic(store, topic_name, desc, writer_qos, vtime_wall_ns(), &c->topic_id, err) < 0) goto fail;
  *out = c;
  return 0;
fail:
  capture_destroy(c);
  return -1;
}

void capture_destroy(capture_t *c) {
  if (!c) return;
  if (c->reader > 0) dds_delete(c->reader);
  if (c->topic > 0) dds_delete(c->topic);
  handle_set_free(&c->unknown_handles);
  handle_set_free(&c->ended);
  free(c->writers);
  free(c->buf);
  free(c->topic_name);
  free(c->type_name);
  free(c);
}

const char *capture_topic_name(const capture_t *c) { return c->topic_name; }
const char *capture_type_name(const capture_t *c) { return c->type_name; }
dds_entity_t capture_reader(const capture_t *c) { return c->reader; }

const char *capture_incompatibility(const capture_t *c, const dds_qos_t *wq) {
  dds_reliability_kind_t rel = DDS_RELIABILITY_RELIABLE;
  dds_duration_t blocking;
  if (wq) dds_qget_reliability(wq, &rel, &blocking);
  if (c->reliability == DDS_RELIABILITY_RELIABLE && rel == DDS_RELIABILITY_BEST_EFFORT)
    return "it is best-effort and the recorder's reader for this topic is reliable";
  dds_durability_kind_t dur = DDS_DURABILITY_VOLATILE;
  if (wq) dds_qget_durability(wq, &dur);
  if (dur < c->durability) return "it is volatile and the recorder's reader for this topic is transient-local";
  dds_ownership_kind_t own = DDS_OWNERSHIP_SHARED;
  if (wq) dds_qget_ownership(wq, &own);
  if (own != c->ownership) return "its ownership kind differs from the recorder's reader for this topic";
  return NULL;
}

static cap_writer_t *writer_by_guid(capture_t *c, const uint8_t guid[16]) {
  for (size_t i = 0; i < c->nwriters; i++)
    if (memcmp(c->writers[i].guid, guid, 16) == 0) return &c->writers[i];
  return NULL;
}

static cap_writer_t *append_writer(capture_t *c, store_t *store, const uint8_t guid[16], const char *partitions,
                                   verr_t *err) {
  if (c->nwriters == c->capwriters) {
    size_t ncap = c->capwriters ? 2 * c->capwriters : 8;
    cap_writer_t *n = realloc(c->writers, ncap * sizeof *n);
    if (!n) {
      verr_set(err, "out of memory");
      return NULL;
    }
    c->writers = n;
    c->capwriters = ncap;
  }
  cap_writer_t *w = &c->writers[c->nwriters];
  memset(w, 0, sizeof *w);
  memcpy(w->guid, guid, 16);
  if (store_add_writer(store, c->topic_id, guid, partitions, vtime_wall_ns(), &w->id, err) < 0) return NULL;
  c->nwriters++;
  return w;
}

int capture_add_writer(capture_t *c, store_t *store, const dds_guid_t *guid, const char *partitions, verr_t *err) {
  if (writer_by_guid(c, guid->v)) return 0;
  return append_writer(c, store, guid->v, partitions, err) ? 0 : -1;
}

/* The writer row of a sample. The sample info only carries the local
 * publication handle; the GUID behind it comes from the reader's matched
 * publication data, asked once per handle. */
static int64_t writer_id_for(capture_t *c, store_t *store, dds_instance_handle_t ph, verr_t *err, int *fail) {
  if (ph == 0) return 0;
  for (size_t i = 0; i < c->nwriters; i++)
    if (c->writers[i].handle == ph) return c->writers[i].id;
  if (handle_set_contains(&c->unknown_handles, ph)) return 0;
  dds_builtintopic_endpoint_t *ep = dds_get_matched_publication_data(c->reader, ph);
  if (!ep) {
    /* The writer left before we asked: keep its samples, writer unknown. */
    handle_set_add(&c->unknown_handles, ph);
    return 0;
  }
  cap_writer_t *w = writer_by_guid(c, ep->key.v);
  if (!w) {
    char parts[512];
    discovery_partition_matches("*", ep->qos, parts, sizeof parts);
    w = append_writer(c, store, ep->key.v, parts, err);
  }
  dds_builtintopic_free_endpoint(ep);
  if (!w) {
    *fail = 1;
    return 0;
  }
  w->handle = ph;
  return w->id;
}

static int cmp_entry(const void *a, const void *b) {
  const cap_entry_t *x = a, *y = b;
  if (x->ts != y->ts) return x->ts < y->ts ? -1 : 1;
  return x->seq < y->seq ? -1 : x->seq > y->seq;
}

static uint8_t ended_kind(dds_instance_state_t st) {
  return st == DDS_IST_NOT_ALIVE_DISPOSED ? REC_KIND_DISPOSE : REC_KIND_UNREGISTER;
}

/* Builds the rows of one take: every sample, plus an inferred
 * dispose/unregister after the last sample of an instance that is no
 * longer alive when no key-only sample in the take says so already.
 * Samples of one instance are contiguous in a take. */
static size_t plan_rows(capture_t *c, uint32_t n) {
  size_t ne = 0;
  uint32_t run = 0;
  for (uint32_t i = 0; i < n; i++) {
    const dds_sample_info_t *si = &c->si[i];
    cap_entry_t *e = &c->entries[ne++];
    e->ts = si->source_timestamp;
    e->seq = 2 * i;
    e->idx = (uint16_t)i;
    e->inferred = 0;
    e->kind = si->valid_data ? REC_KIND_DATA : ended_kind(si->instance_state);
    bool run_end = i + 1 == n || c->si[i + 1].instance_handle != si->instance_handle;
    if (!run_end) continue;
    bool run_has_keyonly = false;
    for (uint32_t j = run; j <= i; j++)
      if (!c->si[j].valid_data) run_has_keyonly = true;
    dds_instance_handle_t ih = si->instance_handle;
    if (si->instance_state == DDS_IST_ALIVE) {
      handle_set_remove(&c->ended, ih);
    } else {
      if (!run_has_keyonly && si->valid_data && !handle_set_contains(&c->ended, ih)) {
        cap_entry_t *d = &c->entries[ne++];
        *d = *e;
        d->seq = 2 * i + 1;
        d->inferred = 1;
        d->kind = ended_kind(si->instance_state);
      }
      handle_set_add(&c->ended, ih);
    }
    run = i + 1;
  }
  qsort(c->entries, ne, sizeof c->entries[0], cmp_entry);
  return ne;
}

int capture_drain(capture_t *c, store_t *store, uint64_t *rows, verr_t *err) {
  handle_set_clear(&c->ended);
  for (;;) {
    for (int i = 0; i < CHUNK; i++) c->sd[i] = NULL;
    dds_return_t n = dds_takecdr(c->reader, c->sd, CHUNK, c->si, DDS_ANY_STATE);
    if (n < 0) {
      verr_set(err, "DDS: take on '%s' failed: %s", c->topic_name, dds_strretcode(n));
      return CAPTURE_ERR_DDS;
    }
    if (n == 0) return 0;
    int64_t recv = vtime_wall_ns();
    size_t ne = plan_rows(c, (uint32_t)n);
    int ret = 0;
    for (size_t k = 0; k < ne && ret == 0; k++) {
      const cap_entry_t *e = &c->entries[k];
      struct ddsi_serdata *sd = c->sd[e->idx];
      size_t sz = sd ? ddsi_serdata_size(sd) : 0;
      if (sz > c->bufcap) {
        size_t ncap = c->bufcap ? c->bufcap : 4096;
        while (ncap < sz) ncap *= 2;
        unsigned char *nb = realloc(c->buf, ncap);
        if (!nb) {
          ret = verr_set(err, "out of memory for a %zu-byte sample of '%s'", sz, c->topic_name);
          break;
        }
        c->buf = nb;
        c->bufcap = ncap;
      }
      if (sz) ddsi_serdata_to_ser(sd, 0, sz, c->buf);
      int fail = 0;
      store_sample_t s = {
          .topic_id = c->topic_id,
          .writer_id = writer_id_for(c, store, c->si[e->idx].publication_handle, err, &fail),
          .source_ts_ns = e->ts,
          .recv_wall_ns = recv,
          .kind = e->kind,
          .inferred = e->inferred,
          .cdr = c->buf,
          .cdr_len = sz,
      };
      if (fail || store_add_sample(store, &s, err) < 0)
        ret = -1;
      else
        (*rows)++;
    }
    /* Every serdata handed out by takecdr holds a reference. */
    for (int i = 0; i < n; i++)
      if (c->sd[i]) ddsi_serdata_unref(c->sd[i]);
    if (ret < 0) return CAPTURE_ERR_STORE;
    if (n < CHUNK) return 0;
  }
}
