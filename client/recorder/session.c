/* SPDX-License-Identifier: Apache-2.0 */
#include "session.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "capture.h"
#include "discovery.h"
#include "participants.h"
#include "dds/vdds.h"
#include "dds/vdds_config.h"
#include "dds/vdds_ident.h"
#include "recording/store.h"
#include "topic_type.h"
#include "vtime.h"

/* A writer on a topic whose type is not resolved yet. */
typedef struct pending {
  disc_writer_t *w;
  uint64_t next_try_ns; /* monotonic */
  uint64_t give_up_ns;
} pending_t;

struct rec_session {
  rec_session_opts_t o;
  store_t *store;
  dds_entity_t participant;
  dds_entity_t subscriber;
  dds_entity_t waitset;
  discovery_t *disc;
  participants_t *parts; /* who is in the domain (participants.h) */
  capture_t **caps;
  size_t ncaps, capcaps;
  pending_t *pend;
  size_t npend, cappend;
  uint32_t failed_topics;
  uint64_t rows;
  /* First fatal error seen inside a discovery callback. */
  int cb_failed;
  verr_t cb_err;
};

#define LOG(s, ...)                                                                                                    \
  do {                                                                                                                 \
    if ((s)->o.log) {                                                                                                  \
      fprintf((s)->o.log, "recorder: " __VA_ARGS__);                                                                   \
      fputc('\n', (s)->o.log);                                                                                         \
    }                                                                                                                  \
  } while (0)

static capture_t *find_capture(rec_session_t *s, const char *topic) {
  for (size_t i = 0; i < s->ncaps; i++)
    if (strcmp(capture_topic_name(s->caps[i]), topic) == 0) return s->caps[i];
  return NULL;
}

static void add_writer_to(rec_session_t *s, capture_t *c, const disc_writer_t *w) {
  if (strcmp(capture_type_name(c), w->type_name) != 0) {
    LOG(s, "topic %s: writer with type %s ignored, recording type %s (one type per topic)", w->topic_name, w->type_name,
        capture_type_name(c));
    return;
  }
  const char *why = capture_incompatibility(c, w->qos);
  if (why) LOG(s, "topic %s: a writer's samples will not be recorded: %s", w->topic_name, why);
  if (capture_add_writer(c, s->store, &w->guid, w->partitions, &s->cb_err) < 0) s->cb_failed = 1;
}

static void on_writer(void *arg, const disc_writer_t *w) {
  rec_session_t *s = arg;
  /* Keyframe chunks are a transport copy of MeshState's keyframes for lossy
   * links (dds/key_chunks.h): MeshState is the keyframe of record, so a
   * recording keeps the format every reader knows and no keyframe twice. */
  if (strcmp(w->topic_name, vdds_topic_name(VT_MESH_KEY_CHUNK)) == 0) return;
  capture_t *c = find_capture(s, w->topic_name);
  if (c) {
    add_writer_to(s, c, w);
    return;
  }
  for (size_t i = 0; i < s->npend; i++)
    if (memcmp(&s->pend[i].w->guid, &w->guid, sizeof w->guid) == 0) return; /* already queued */
  if (s->npend == s->cappend) {
    size_t n = s->cappend ? 2 * s->cappend : 8;
    pending_t *p = realloc(s->pend, n * sizeof *p);
    if (!p) {
      LOG(s, "topic %s: out of memory, writer ignored", w->topic_name);
      return;
    }
    s->pend = p;
    s->cappend = n;
  }
  disc_writer_t *copy = disc_writer_dup(w);
  if (!copy) {
    LOG(s, "topic %s: out of memory, writer ignored", w->topic_name);
    return;
  }
  uint64_t now = vtime_mono_ns();
  s->pend[s->npend++] = (pending_t){copy, now, now + (uint64_t)s->o.type_give_up};
}

static void drop_pending(rec_session_t *s, size_t i) {
  disc_writer_free(s->pend[i].w);
  s->pend[i] = s->pend[--s->npend];
}

static int attach_capture(rec_session_t *s, capture_t *c, verr_t *err) {
  if (s->ncaps == s->capcaps) {
    size_t n = s->capcaps ? 2 * s->capcaps : 8;
    capture_t **p = realloc(s->caps, n * sizeof *p);
    if (!p) return verr_set(err, "out of memory");
    s->caps = p;
    s->capcaps = n;
  }
  dds_entity_t rc = dds_create_readcondition(capture_reader(c), DDS_ANY_STATE);
  if (rc < 0 || dds_waitset_attach(s->waitset, rc, 0) < 0)
    return verr_set(err, "DDS: cannot watch reader of %s", capture_topic_name(c));
  s->caps[s->ncaps++] = c;
  return 0;
}

/* Tries to resolve the types of queued writers whose retry time has come.
 * Writers queued for a topic that got its capture meanwhile join it. */
static void resolve_pending(rec_session_t *s) {
  uint64_t now = vtime_mono_ns();
  for (size_t i = 0; i < s->npend;) {
    pending_t *p = &s->pend[i];
    capture_t *c = find_capture(s, p->w->topic_name);
    if (c) {
      add_writer_to(s, c, p->w);
      drop_pending(s, i);
      continue;
    }
    bool earlier_same_topic = false;
    for (size_t j = 0; j < i; j++)
      if (strcmp(s->pend[j].w->topic_name, p->w->topic_name) == 0) earlier_same_topic = true;
    /* One lookup per topic at a time: every attempt may block for
     * type_attempt, and other writers of the topic share its type. */
    if (p->next_try_ns > now || earlier_same_topic) {
      i++;
      continue;
    }
    verr_t err = {{0}};
    dds_topic_descriptor_t *desc = NULL;
    topic_type_result_t r =
        topic_type_resolve(s->participant, p->w->type_name, p->w->qos, s->o.type_attempt, &desc, &err);
    now = vtime_mono_ns();
    if (r == TOPIC_TYPE_RETRY && now < p->give_up_ns) {
      p->next_try_ns = now + (uint64_t)s->o.type_retry;
      i++;
      continue;
    }
    if (r != TOPIC_TYPE_OK) {
      LOG(s, "topic %s: NOT recorded: %s", p->w->topic_name, err.msg);
      s->failed_topics++;
      drop_pending(s, i);
      continue;
    }
    int rc = capture_create(&c, s->participant, s->subscriber, p->w->topic_name, desc, p->w->qos, s->o.depth, s->store,
                            &err);
    dds_delete_topic_descriptor(desc);
    if (rc < 0 || attach_capture(s, c, &err) < 0) {
      LOG(s, "topic %s: NOT recorded: %s", p->w->topic_name, err.msg);
      if (rc == 0) capture_destroy(c);
      s->failed_topics++;
      drop_pending(s, i);
      continue;
    }
    LOG(s, "recording topic %s (type %s, partition %s)", p->w->topic_name, p->w->type_name, p->w->partitions);
    add_writer_to(s, c, p->w);
    drop_pending(s, i);
  }
}

int rec_session_open(rec_session_t **out, const rec_session_opts_t *opts, const char *recorder_version, verr_t *err) {
  *out = NULL;
  rec_session_t *s = calloc(1, sizeof *s);
  if (!s) return verr_set(err, "out of memory");
  s->o = *opts;
  if (s->o.type_attempt <= 0) s->o.type_attempt = REC_SESSION_DEFAULT_TYPE_ATTEMPT;
  if (s->o.type_retry <= 0) s->o.type_retry = REC_SESSION_DEFAULT_TYPE_RETRY;
  if (s->o.type_give_up <= 0) s->o.type_give_up = REC_SESSION_DEFAULT_TYPE_GIVE_UP;
  char host[256] = "";
  if (gethostname(host, sizeof host - 1) != 0) host[0] = 0;
  store_session_t meta = {opts->scene, opts->partition, opts->domain, vtime_wall_ns(), host, recorder_version};
  /* The loopback configuration by default; off loopback, DDS Security or
   * an explicit --insecure (vdds_config.h): refused before any file. */
  if (vdds_config_prepare(stderr, "recorder", err) || store_open(&s->store, opts->out, opts->force, &meta, err) < 0) {
    free(s);
    return -1;
  }
  dds_qos_t *pq = vdds_participant_qos();
  s->participant = dds_create_participant((dds_domainid_t)opts->domain, pq, NULL);
  if (pq) dds_delete_qos(pq);
  if (s->participant < 0) {
    verr_set(err, "DDS: cannot create participant on domain %d: %s (check CYCLONEDDS_URI)", opts->domain,
             dds_strretcode(s->participant));
    goto fail;
  }
  dds_qos_t *q = dds_create_qos();
  dds_qset_partition1(q, opts->partition);
  s->subscriber = dds_create_subscriber(s->participant, q, NULL);
  dds_delete_qos(q);
  if (s->subscriber < 0) {
    verr_set(err, "DDS: cannot create subscriber in partition '%s': %s", opts->partition,
             dds_strretcode(s->subscriber));
    goto fail;
  }
  s->waitset = dds_create_waitset(s->participant);
  if (s->waitset < 0) {
    verr_set(err, "DDS: cannot create waitset: %s", dds_strretcode(s->waitset));
    goto fail;
  }
  if (discovery_open(&s->disc, s->participant, opts->partition, err) < 0) goto fail;
  if (participants_open(&s->parts, s->participant, err) < 0) goto fail;
  dds_entity_t rc = dds_create_readcondition(discovery_reader(s->disc), DDS_ANY_STATE);
  if (rc < 0 || dds_waitset_attach(s->waitset, rc, 0) < 0) {
    verr_set(err, "DDS: cannot watch DCPSPublication");
    goto fail;
  }
  *out = s;
  return 0;
fail:
  participants_close(s->parts);
  discovery_close(s->disc);
  if (s->participant > 0) dds_delete(s->participant);
  store_close(s->store, -1, NULL);
  /* Nothing was recorded: do not leave an empty file behind. */
  unlink(opts->out);
  free(s);
  return -1;
}

static int drain_all(rec_session_t *s, verr_t *err) {
  for (size_t i = 0; i < s->ncaps; i++) {
    verr_t e = {{0}};
    int rc = capture_drain(s->caps[i], s->store, &s->rows, &e);
    /* A store failure ends the recording; a DDS take failure is logged
     * and retried on the next step. */
    if (rc == CAPTURE_ERR_DDS)
      LOG(s, "%s", e.msg);
    else if (rc < 0)
      return verr_set(err, "%s", e.msg);
  }
  return 0;
}

int rec_session_step(rec_session_t *s, dds_duration_t timeout, verr_t *err) {
  dds_waitset_wait(s->waitset, NULL, 0, timeout);
  int n = discovery_poll(s->disc, on_writer, s);
  if (n < 0) LOG(s, "DDS: reading DCPSPublication failed: %s", dds_strretcode(n));
  if (s->cb_failed) return verr_set(err, "%s", s->cb_err.msg);
  if (participants_poll(s->parts, s->store, s->o.log, err) < 0) return -1;
  if (s->npend) resolve_pending(s);
  if (s->cb_failed) return verr_set(err, "%s", s->cb_err.msg);
  if (drain_all(s, err) < 0) return -1;
  return store_commit_if_due(s->store, vtime_mono_ns(), err);
}

void rec_session_get_stats(const rec_session_t *s, rec_session_stats_t *st) {
  store_counts(s->store, &st->samples, &st->bytes);
  st->topics = (uint32_t)s->ncaps;
  st->failed_topics = s->failed_topics;
  st->disk_full = store_disk_full(s->store);
}

int rec_session_close(rec_session_t *s, rec_session_stats_t *final, verr_t *err) {
  int ret = drain_all(s, err);
  verr_t perr;
  /* Last discovery news (a participant that left just now) before closing;
   * a failure here is the store's and drain_all already reported it. */
  if (ret == 0 && participants_poll(s->parts, s->store, s->o.log, &perr) < 0) ret = verr_set(err, "%s", perr.msg);
  participants_close(s->parts);
  if (final) rec_session_get_stats(s, final);
  for (size_t i = 0; i < s->npend; i++) {
    LOG(s, "topic %s: NOT recorded: type still unresolved at exit", s->pend[i].w->topic_name);
    disc_writer_free(s->pend[i].w);
  }
  free(s->pend);
  /* Readers go before the store closes so no DDS callback outlives it;
   * deleting the participant removes the waitset and conditions too. */
  for (size_t i = 0; i < s->ncaps; i++) capture_destroy(s->caps[i]);
  free(s->caps);
  discovery_close(s->disc);
  dds_delete(s->participant);
  verr_t e2;
  if (store_close(s->store, vtime_wall_ns(), ret == 0 ? err : &e2) < 0) ret = -1;
  free(s);
  return ret;
}
