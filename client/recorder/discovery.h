/* SPDX-License-Identifier: Apache-2.0 */
/* discovery: which writers exist, on which topics, in the recorded partition.
 *
 * Reads the DCPSPublication built-in topic of the recorder's participant
 * and reports every live writer whose partition matches the recorded
 * partition pattern. Knows nothing about types or storage: the session
 * decides what to do with a writer. Not thread-safe. */
#ifndef VISCERA_REC_DISCOVERY_H
#define VISCERA_REC_DISCOVERY_H

#include <stdbool.h>
#include <stddef.h>

#include <dds/dds.h>

#include "verr.h"

/* A discovered writer. Pointers are valid only during the callback; use
 * disc_writer_dup to keep one. */
typedef struct disc_writer {
  dds_guid_t guid;
  const char *topic_name;
  const char *type_name;
  /* Its QoS as discovered (partition, reliability, durability, type
   * information, ...). With DDS_HAS_TYPE_DISCOVERY this holds the XTypes
   * type information dds_builtintopic_get_endpoint_type_info returns. */
  const dds_qos_t *qos;
  /* Its partitions joined with ',' ("" for the default partition). */
  const char *partitions;
} disc_writer_t;

typedef struct discovery discovery_t;

typedef void (*discovery_cb)(void *arg, const disc_writer_t *w);

/* `pattern` is the partition pattern (fnmatch(3) syntax, no flags). */
int discovery_open(discovery_t **out, dds_entity_t participant, const char *pattern, verr_t *err);
void discovery_close(discovery_t *d);

/* The DCPSPublication reader, to attach to a waitset. */
dds_entity_t discovery_reader(const discovery_t *d);

/* Takes pending DCPSPublication samples and calls `cb` for every alive
 * writer in a matching partition. A writer may be reported again when its
 * QoS changes. Returns the number reported or a negative DDS return code. */
int discovery_poll(discovery_t *d, discovery_cb cb, void *arg);

/* True when one of the partitions in `qos` (the default partition "" when
 * it has none) matches `pattern`. Writes the joined partition list to
 * `joined` (truncated to `size`) when joined != NULL. */
bool discovery_partition_matches(const char *pattern, const dds_qos_t *qos, char *joined, size_t size);

/* Deep copy / free of a disc_writer_t (the copy owns its strings and QoS). */
disc_writer_t *disc_writer_dup(const disc_writer_t *w);
void disc_writer_free(disc_writer_t *w);

#endif
