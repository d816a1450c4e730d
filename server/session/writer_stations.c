/* SPDX-License-Identifier: Apache-2.0 */
#include "session/writer_stations.h"

#include <stdio.h>
#include <string.h>

void writer_stations_init(writer_stations_t *ws) { memset(ws, 0, sizeof *ws); }

const char *writer_stations_find(const writer_stations_t *ws, dds_instance_handle_t h) {
  for (size_t i = 0; i < ws->n; i++)
    if (ws->handle[i] == h) return ws->station[i];
  return NULL;
}

const char *writer_stations_put(writer_stations_t *ws, dds_instance_handle_t h, const char *station) {
  size_t slot = ws->n;
  if (slot < WRITER_STATIONS_CAP) {
    ws->n++;
  } else { /* full: replace the entry cached longest (slots fill in order, then rotate) */
    slot = ws->next_evict;
    ws->next_evict = (ws->next_evict + 1) % WRITER_STATIONS_CAP;
    ws->evictions++;
  }
  ws->handle[slot] = h;
  snprintf(ws->station[slot], sizeof ws->station[slot], "%s", station ? station : "");
  return ws->station[slot];
}

const char *writer_stations_get(writer_stations_t *ws, dds_entity_t reader, dds_instance_handle_t h) {
  const char *s = writer_stations_find(ws, h);
  if (s) return s;
  ws->lookups++;
  if (vdds_station_of_writer(reader, h, ws->scratch) != 0) return ws->scratch; /* gone: "" , not cached */
  return writer_stations_put(ws, h, ws->scratch);
}
