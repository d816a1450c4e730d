/* rec_topology: reads a session recording straight from the SQLite file and
 * prints every recorded MeshState keyframe and EVENT_TOPOLOGY_CHANGED
 * SessionEvent, decoded with the compiled-in descriptors:
 *   MESHSTATE organ=N topology=V keyframe=K vertices=NV triangles=NT
 *   TOPOLOGY_EVENT organ=N value=X text
 * Exit 1 when the file cannot be read or a sample does not decode.
 * usage: rec_topology FILE.db */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <dds/dds.h>
#include <dds/ddsi/ddsi_cdrstream.h>
#include <sqlite3.h>

#include "viscera.h"

/* Decodes a stored sample (4-byte encoding header + payload) into `out`
 * with the compiled-in descriptor's ops (as rec_check does). */
static bool decode(const unsigned char *cdr, int len, const dds_topic_descriptor_t *desc, void *out) {
  if (len < 4 || cdr[0] != 0) return false;
  unsigned id = cdr[1];
  bool le = (id & 1u) != 0;
  uint32_t xcdrv = id <= 3 ? 1 : 2;
  uint32_t size = (uint32_t)len - 4;
  void *buf = malloc(size ? size : 1);
  if (!buf) return false;
  memcpy(buf, cdr + 4, size);
  uint32_t off = 0;
  bool bswap = le != (DDSRT_ENDIAN == DDSRT_LITTLE_ENDIAN);
  bool ok = dds_stream_normalize_data(buf, &off, size, bswap, xcdrv, desc->m_ops) != NULL;
  if (ok) {
    dds_istream_t is;
    dds_istream_init(&is, size, buf, xcdrv);
    dds_stream_read(&is, out, desc->m_ops);
    dds_istream_fini(&is);
  }
  free(buf);
  return ok;
}

static sqlite3_stmt *samples_of(sqlite3 *db, const char *topic) {
  char sql[256];
  snprintf(sql, sizeof sql,
           "SELECT s.cdr FROM samples s JOIN topics t ON t.id=s.topic_id WHERE t.name='%s' AND s.kind=0 ORDER BY s.id",
           topic);
  sqlite3_stmt *st = NULL;
  if (sqlite3_prepare_v2(db, sql, -1, &st, NULL) != SQLITE_OK) {
    fprintf(stderr, "rec_topology: %s\n", sqlite3_errmsg(db));
    return NULL;
  }
  return st;
}

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: rec_topology FILE.db\n");
    return 2;
  }
  sqlite3 *db = NULL;
  if (sqlite3_open_v2(argv[1], &db, SQLITE_OPEN_READONLY, NULL) != SQLITE_OK) {
    fprintf(stderr, "rec_topology: %s: %s\n", argv[1], sqlite3_errmsg(db));
    sqlite3_close(db);
    return 1;
  }
  int bad = 0;
  sqlite3_stmt *st = samples_of(db, "viscera_MeshState");
  while (st && sqlite3_step(st) == SQLITE_ROW) {
    viscera_MeshState m;
    memset(&m, 0, sizeof m);
    if (!decode(sqlite3_column_blob(st, 0), sqlite3_column_bytes(st, 0), &viscera_MeshState_desc, &m)) {
      bad++;
      continue;
    }
    printf("MESHSTATE organ=%u topology=%u keyframe=%u vertices=%u triangles=%u\n", m.organ_id, m.topology_version,
           m.keyframe_seq, m.positions._length / 3, m.triangles._length / 3);
    dds_sample_free(&m, &viscera_MeshState_desc, DDS_FREE_CONTENTS);
  }
  sqlite3_finalize(st);
  st = samples_of(db, "viscera_SessionEvent");
  while (st && sqlite3_step(st) == SQLITE_ROW) {
    viscera_SessionEvent e;
    memset(&e, 0, sizeof e);
    if (!decode(sqlite3_column_blob(st, 0), sqlite3_column_bytes(st, 0), &viscera_SessionEvent_desc, &e)) {
      bad++;
      continue;
    }
    if (e.kind == viscera_EVENT_TOPOLOGY_CHANGED)
      printf("TOPOLOGY_EVENT organ=%d value=%.0f %s\n", (int)e.organ_id, e.value, e.text);
  }
  sqlite3_finalize(st);
  sqlite3_close(db);
  if (bad) fprintf(stderr, "rec_topology: %d samples did not decode\n", bad);
  return bad ? 1 : 0;
}
