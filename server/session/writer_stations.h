/* SPDX-License-Identifier: Apache-2.0 */
/* writer_stations: the station each ToolCommand writer announced, per
 * publication handle (idl ToolRole; vdds.h vdds_station_of_writer).
 *
 * Finding a writer's USER_DATA costs a lookup (and an allocation) in
 * Cyclone's matched-endpoint table, too much for every sample of a 1 kHz
 * stream; a handle never changes its USER_DATA, so the answer is cached.
 * The table is small and bounded (a seat has a handful of writers); when
 * it is full the entry cached longest is evicted, which costs at most one
 * more lookup if that writer is still sending. A writer that is no longer
 * matched (it left after its sample was queued) is anonymous and not
 * cached.
 *
 * The station is a claim the writer makes, not an identity: DDS Security
 * binds a participant to its seat's partition, not to a station name. */
#ifndef VISCERA_WRITER_STATIONS_H
#define VISCERA_WRITER_STATIONS_H

#include <dds/dds.h>
#include <stddef.h>
#include <stdint.h>

#include "dds/vdds.h"

#define WRITER_STATIONS_CAP 32

typedef struct writer_stations {
  dds_instance_handle_t handle[WRITER_STATIONS_CAP];
  char station[WRITER_STATIONS_CAP][VDDS_STATION_MAX];
  size_t n, next_evict;
  char scratch[VDDS_STATION_MAX]; /* the answer for a writer not cached */
  uint64_t lookups, evictions;    /* how often the DDS lookup ran, entries dropped */
} writer_stations_t;

void writer_stations_init(writer_stations_t *ws);

/* Cached station of `h`, or NULL when not cached. */
const char *writer_stations_find(const writer_stations_t *ws, dds_instance_handle_t h);

/* Caches station (copied) for h, evicting the oldest entry when full;
 * returns the cached copy. */
const char *writer_stations_put(writer_stations_t *ws, dds_instance_handle_t h, const char *station);

/* The station of the writer `h` of a sample taken from `reader`: cached,
 * or looked up once and cached. The string stays valid until the next call. */
const char *writer_stations_get(writer_stations_t *ws, dds_entity_t reader, dds_instance_handle_t h);

#endif
