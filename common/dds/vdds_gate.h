/* SPDX-License-Identifier: Apache-2.0 */
/* vdds_gate: what a keyed reader lets in from the network, decided before
 * Cyclone stores a sample (issue 15.1).
 *
 * A reader keeps one instance per key value it has seen for as long as any
 * writer that wrote it is alive, and keep-last history is per instance,
 * not per writer: a flood of new key values grows memory without bound,
 * and a flood aimed at one key evicts the legitimate writer's samples
 * before the application takes them. A gate is a Cyclone topic filter on a
 * topic entity of the reader's own (vdds_reader_gated): a sample is
 * dropped, counted, before it creates an instance or takes a place in the
 * history, when
 *   - its key (the first member of every keyed viscera type, a 32-bit
 *     index: organ, tool, object, source) is not below `key_bound`;
 *   - `check` (optional) refuses its content (a reason code 1..7);
 *   - its writer (publication handle) was blocked for that key, or for
 *     every key, by the application (vdds_gate_block), e.g. after seeing
 *     that the writer is not the seat's server or not the tool's station.
 * A writer not yet blocked gets its first samples through, so the
 * application can judge it: blocking is the application's verdict, the
 * gate only makes it stick. The blocked table is bounded
 * (VDDS_GATE_BLOCK_CAP, the oldest entry is recycled).
 *
 * Threads: the filter runs on Cyclone's receive threads with the reader's
 * cache locked; it calls no DDS function, takes only the gate's own lock
 * (a leaf) and updates atomic counters. The other functions may be called
 * from any thread. The gate must outlive its reader. */
#ifndef VISCERA_VDDS_GATE_H
#define VISCERA_VDDS_GATE_H

#include <dds/dds.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>

#include "dds/vdds.h"

#define VDDS_GATE_BLOCK_CAP 64
#define VDDS_GATE_ANY_KEY UINT32_MAX /* vdds_gate_block: every key of that writer */
#define VDDS_GATE_REASONS 8

/* 0: accept; 1..VDDS_GATE_REASONS-1: refuse, counted under that code. */
typedef int (*vdds_gate_check_fn)(const void *sample, void *arg);

typedef struct vdds_gate {
  uint32_t key_bound; /* keys >= this are refused; 0 = no bound */
  vdds_gate_check_fn check;
  void *check_arg;
  pthread_mutex_t lock;
  struct {
    dds_instance_handle_t writer;
    uint32_t key;
  } blocked[VDDS_GATE_BLOCK_CAP];
  size_t nblocked, next_recycle;
  _Atomic uint64_t passed;       /* samples let in */
  _Atomic uint64_t out_of_range; /* key >= key_bound */
  _Atomic uint64_t refused;      /* refused by check */
  _Atomic uint64_t from_blocked; /* from a blocked writer */
  _Atomic uint64_t reason[VDDS_GATE_REASONS];
  _Atomic uint32_t last_refused_key; /* key of the last sample refused by range or check */
} vdds_gate_t;

void vdds_gate_init(vdds_gate_t *g, uint32_t key_bound, vdds_gate_check_fn check, void *check_arg);
void vdds_gate_destroy(vdds_gate_t *g);

/* The verdict of the filter for one sample (pure apart from the counters;
 * tests call it directly): 1 let in, 0 dropped. */
int vdds_gate_accepts(vdds_gate_t *g, const void *sample, dds_instance_handle_t writer);

/* Drops, from now on, `writer`'s samples for `key` (VDDS_GATE_ANY_KEY:
 * every key). Idempotent. */
void vdds_gate_block(vdds_gate_t *g, dds_instance_handle_t writer, uint32_t key);
/* Forgets every block on `key` (VDDS_GATE_ANY_KEY: every block), e.g.
 * when a tool's role changed. */
void vdds_gate_unblock_key(vdds_gate_t *g, uint32_t key);
/* Samples dropped so far (range + check + blocked). */
uint64_t vdds_gate_dropped(vdds_gate_t *g);

/* A topic entity of t of its own (for one reader) carrying gate g, for a
 * reader with QoS of the caller's; negative on failure (err set). */
dds_entity_t vdds_gated_topic(vdds_t *v, vdds_topic_id_t t, vdds_gate_t *g, verr_t *err);

/* A reader of topic t with the table's QoS (history depth `depth` when > 0,
 * and at most `max_instances` instances when > 0), behind gate g: the
 * reader gets a topic entity of its own carrying the filter, so the
 * participant's other readers and its writers of t are not filtered. */
dds_entity_t vdds_reader_gated(vdds_t *v, vdds_topic_id_t t, vdds_gate_t *g, int depth, int max_instances,
                               const dds_listener_t *l, verr_t *err);
/* The same; live_only != 0 makes it volatile (no history from writers it
 * matches, only their new samples), e.g. a second reader of keyframe chunks
 * that takes the set a server writes again for it (dds/key_chunks.h). */
dds_entity_t vdds_reader_gated_live(vdds_t *v, vdds_topic_id_t t, vdds_gate_t *g, int depth, int max_instances,
                                    int live_only, const dds_listener_t *l, verr_t *err);

#endif
