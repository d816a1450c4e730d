/* SPDX-License-Identifier: Apache-2.0 */
#include "dds/vdds_gate.h"

#include <string.h>

void vdds_gate_init(vdds_gate_t *g, uint32_t key_bound, vdds_gate_check_fn check, void *check_arg) {
  memset(g, 0, sizeof *g);
  g->key_bound = key_bound;
  g->check = check;
  g->check_arg = check_arg;
  pthread_mutex_init(&g->lock, NULL);
  atomic_init(&g->passed, 0);
  atomic_init(&g->out_of_range, 0);
  atomic_init(&g->refused, 0);
  atomic_init(&g->from_blocked, 0);
  atomic_init(&g->last_refused_key, 0);
  for (int i = 0; i < VDDS_GATE_REASONS; i++) atomic_init(&g->reason[i], 0);
}

void vdds_gate_destroy(vdds_gate_t *g) { pthread_mutex_destroy(&g->lock); }

static int is_blocked(vdds_gate_t *g, dds_instance_handle_t writer, uint32_t key) {
  int hit = 0;
  pthread_mutex_lock(&g->lock);
  for (size_t i = 0; i < g->nblocked && !hit; i++)
    hit = g->blocked[i].writer == writer && (g->blocked[i].key == key || g->blocked[i].key == VDDS_GATE_ANY_KEY);
  pthread_mutex_unlock(&g->lock);
  return hit;
}

int vdds_gate_accepts(vdds_gate_t *g, const void *sample, dds_instance_handle_t writer) {
  /* Every keyed viscera type starts with its 32-bit index key (viscera.idl). */
  uint32_t key;
  memcpy(&key, sample, sizeof key);
  if (g->key_bound && key >= g->key_bound) {
    atomic_fetch_add_explicit(&g->out_of_range, 1, memory_order_relaxed);
    atomic_store_explicit(&g->last_refused_key, key, memory_order_relaxed);
    return 0;
  }
  if (g->check) {
    int r = g->check(sample, g->check_arg);
    if (r) {
      atomic_fetch_add_explicit(&g->refused, 1, memory_order_relaxed);
      atomic_fetch_add_explicit(&g->reason[r > 0 && r < VDDS_GATE_REASONS ? r : 0], 1, memory_order_relaxed);
      atomic_store_explicit(&g->last_refused_key, key, memory_order_relaxed);
      return 0;
    }
  }
  if (writer && is_blocked(g, writer, key)) {
    atomic_fetch_add_explicit(&g->from_blocked, 1, memory_order_relaxed);
    return 0;
  }
  atomic_fetch_add_explicit(&g->passed, 1, memory_order_relaxed);
  return 1;
}

void vdds_gate_block(vdds_gate_t *g, dds_instance_handle_t writer, uint32_t key) {
  pthread_mutex_lock(&g->lock);
  int have = 0;
  for (size_t i = 0; i < g->nblocked && !have; i++) have = g->blocked[i].writer == writer && g->blocked[i].key == key;
  if (!have) {
    size_t slot = g->nblocked;
    if (slot < VDDS_GATE_BLOCK_CAP)
      g->nblocked++;
    else {
      slot = g->next_recycle;
      g->next_recycle = (g->next_recycle + 1) % VDDS_GATE_BLOCK_CAP;
    }
    g->blocked[slot].writer = writer;
    g->blocked[slot].key = key;
  }
  pthread_mutex_unlock(&g->lock);
}

void vdds_gate_unblock_key(vdds_gate_t *g, uint32_t key) {
  pthread_mutex_lock(&g->lock);
  size_t n = 0;
  for (size_t i = 0; i < g->nblocked; i++)
    if (key != VDDS_GATE_ANY_KEY && g->blocked[i].key != key) g->blocked[n++] = g->blocked[i];
  g->nblocked = n;
  g->next_recycle = 0;
  pthread_mutex_unlock(&g->lock);
}

uint64_t vdds_gate_dropped(vdds_gate_t *g) {
  return atomic_load(&g->out_of_range) + atomic_load(&g->refused) + atomic_load(&g->from_blocked);
}

static bool gate_filter(const void *sample, const dds_sample_info_t *si, void *arg) {
  return vdds_gate_accepts(arg, sample, si ? si->publication_handle : 0) != 0;
}

dds_entity_t vdds_gated_topic(vdds_t *v, vdds_topic_id_t t, vdds_gate_t *g, verr_t *err) {
  dds_qos_t *q = vdds_topic_qos(t);
  /* A topic entity of this reader's own: Cyclone filters per topic entity,
   * and a filtered topic would also filter the participant's writes. */
  dds_entity_t tp = dds_create_topic(v->participant, vdds_topic_desc(t), vdds_topic_name(t), q, NULL);
  dds_delete_qos(q);
  struct dds_topic_filter f = {
      .mode = DDS_TOPIC_FILTER_SAMPLE_SAMPLEINFO_ARG, .f = {.sample_sampleinfo_arg = gate_filter}, .arg = g};
  dds_return_t rc = tp < 0 ? tp : dds_set_topic_filter_extended(tp, &f);
  if (rc < 0) {
    verr_set(err, "DDS: cannot create a gated topic for %s: %s", vdds_topic_name(t), dds_strretcode(rc));
    return rc;
  }
  return tp;
}

dds_entity_t vdds_reader_gated(vdds_t *v, vdds_topic_id_t t, vdds_gate_t *g, int depth, int max_instances,
                               const dds_listener_t *l, verr_t *err) {
  return vdds_reader_gated_live(v, t, g, depth, max_instances, 0, l, err);
}

dds_entity_t vdds_reader_gated_live(vdds_t *v, vdds_topic_id_t t, vdds_gate_t *g, int depth, int max_instances,
                                    int live_only, const dds_listener_t *l, verr_t *err) {
  dds_entity_t tp = vdds_gated_topic(v, t, g, err);
  if (tp < 0) return tp;
  dds_qos_t *q = vdds_topic_qos(t);
  if (live_only) dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  if (depth > 0) dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
  if (max_instances > 0) dds_qset_resource_limits(q, DDS_LENGTH_UNLIMITED, max_instances, DDS_LENGTH_UNLIMITED);
  dds_entity_t r = dds_create_reader(v->subscriber, tp, q, l);
  dds_delete_qos(q);
  if (r < 0) verr_set(err, "DDS: cannot create the gated reader for %s: %s", vdds_topic_name(t), dds_strretcode(r));
  return r;
}
