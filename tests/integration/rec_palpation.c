/* rec_palpation: reads a session recording straight from the SQLite file
 * and prints, decoded with the compiled-in descriptors, every palpation
 * threshold SessionEvent and the last Metrics sample per organ:
 *   EVENT up|down LEVEL TOOL TEXT
 *   METRICS organ=N time_above_st=.. time_above_mpf=.. time_above_sft=..
 *           contact_time=.. mean_contact_force=.. path_length=.. peak_force=..
 * Exit 1 when the file cannot be read or a sample does not decode.
 * usage: rec_palpation FILE.db */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <dds/dds.h>
#include <sqlite3.h>

#include "rec_decode.h"
#include "viscera.h"

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: rec_palpation FILE.db\n");
    return 2;
  }
  sqlite3 *db = NULL;
  if (sqlite3_open_v2(argv[1], &db, SQLITE_OPEN_READONLY, NULL) != SQLITE_OK) {
    fprintf(stderr, "rec_palpation: %s: %s\n", argv[1], sqlite3_errmsg(db));
    sqlite3_close(db);
    return 1;
  }
  int bad = 0;
  sqlite3_stmt *st = NULL;
  if (sqlite3_prepare_v2(db,
                         "SELECT s.cdr FROM samples s JOIN topics t ON t.id=s.topic_id"
                         " WHERE t.name='viscera_SessionEvent' AND s.kind=0 ORDER BY s.id",
                         -1, &st, NULL) != SQLITE_OK) {
    fprintf(stderr, "rec_palpation: %s\n", sqlite3_errmsg(db));
    sqlite3_close(db);
    return 1;
  }
  while (sqlite3_step(st) == SQLITE_ROW) {
    viscera_SessionEvent e;
    memset(&e, 0, sizeof e);
    if (!rec_decode_cdr(sqlite3_column_blob(st, 0), (size_t)sqlite3_column_bytes(st, 0), &viscera_SessionEvent_desc,
                        &e)) {
      bad++;
      continue;
    }
    if (e.kind == viscera_EVENT_THRESHOLD_CROSSED_UP || e.kind == viscera_EVENT_THRESHOLD_CROSSED_DOWN)
      printf("EVENT %s %.3f %d %s\n", e.kind == viscera_EVENT_THRESHOLD_CROSSED_UP ? "up" : "down", e.value,
             (int)e.tool_id, e.text);
  }
  sqlite3_finalize(st);

  enum { MAXO = 16 };
  viscera_Metrics last[MAXO];
  int have[MAXO] = {0};
  sqlite3_prepare_v2(db,
                     "SELECT s.cdr FROM samples s JOIN topics t ON t.id=s.topic_id"
                     " WHERE t.name='viscera_Metrics' AND s.kind=0 ORDER BY s.id",
                     -1, &st, NULL);
  while (st && sqlite3_step(st) == SQLITE_ROW) {
    viscera_Metrics m;
    memset(&m, 0, sizeof m);
    if (!rec_decode_cdr(sqlite3_column_blob(st, 0), (size_t)sqlite3_column_bytes(st, 0), &viscera_Metrics_desc, &m)) {
      bad++;
      continue;
    }
    if (m.organ_id < MAXO) {
      last[m.organ_id] = m;
      have[m.organ_id] = 1;
    }
  }
  sqlite3_finalize(st);
  sqlite3_close(db);
  for (int i = 0; i < MAXO; i++)
    if (have[i])
      printf("METRICS organ=%d time_above_st=%.3f time_above_mpf=%.3f time_above_sft=%.3f contact_time=%.3f "
             "mean_contact_force=%.4f path_length=%.4f peak_force=%.4f\n",
             i, last[i].time_above_st, last[i].time_above_mpf, last[i].time_above_sft, last[i].contact_time,
             last[i].mean_contact_force, last[i].path_length, last[i].peak_force);
  if (bad) fprintf(stderr, "rec_palpation: %d samples did not decode\n", bad);
  return bad ? 1 : 0;
}
