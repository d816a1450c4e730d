/* SPDX-License-Identifier: Apache-2.0 */
/* capture: one recorded topic — its reader, its writers, and the path from
 * dds_takecdr to rows in the store.
 *
 * Every sample is taken as serialized data (dds_takecdr), copied out with
 * ddsi_serdata_size / ddsi_serdata_to_ser (the bytes include the 4-byte
 * CDR encoding header) and released with ddsi_serdata_unref. Disposes and
 * unregisters arrive as key-only samples and are stored as such; when
 * Cyclone folds a dispose into the instance state of an unread data sample
 * instead, the capture stores an `inferred` dispose row after it.
 *
 * Within one take the samples are stored in source-timestamp order: Cyclone
 * returns a take grouped by instance, which would otherwise interleave the
 * samples of a multi-instance writer out of order. Not thread-safe. */
#ifndef VISCERA_REC_CAPTURE_H
#define VISCERA_REC_CAPTURE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <dds/dds.h>

#include "recording/store.h"
#include "verr.h"

typedef struct capture capture_t;

/* Reader history depth per instance: how many samples a stall of the
 * recorder can absorb per instance before the oldest are dropped. */
#define CAPTURE_DEFAULT_DEPTH 1000

/* Creates the topic from `desc` (the caller keeps `desc`), a reader in
 * `subscriber` whose reliability, durability, ownership, latency budget and
 * data representation copy `writer_qos` (durability capped at
 * transient-local, the most a reader without a durability service can ask),
 * keep-last `depth`, and the topic's row in the store. */
int capture_create(capture_t **out, dds_entity_t participant, dds_entity_t subscriber, const char *topic_name,
                   const dds_topic_descriptor_t *desc, const dds_qos_t *writer_qos, int32_t depth, store_t *store,
                   verr_t *err);
void capture_destroy(capture_t *c);

const char *capture_topic_name(const capture_t *c);
const char *capture_type_name(const capture_t *c);
dds_entity_t capture_reader(const capture_t *c);

/* Why a writer with `writer_qos` cannot match this capture's reader, or
 * NULL when it can. */
const char *capture_incompatibility(const capture_t *c, const dds_qos_t *writer_qos);

/* Records a writer of this topic (once per GUID). */
int capture_add_writer(capture_t *c, store_t *store, const dds_guid_t *guid, const char *partitions, verr_t *err);

/* Takes everything the reader holds and appends it to the store. Adds the
 * number of rows stored to *rows. Returns 0, CAPTURE_ERR_STORE when the
 * store failed (the recording cannot go on) or CAPTURE_ERR_DDS when the
 * take failed (worth retrying later); err says what happened. */
#define CAPTURE_ERR_STORE (-1)
#define CAPTURE_ERR_DDS (-2)
int capture_drain(capture_t *c, store_t *store, uint64_t *rows, verr_t *err);

#endif
