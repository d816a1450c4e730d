/* rec_palpation: reads a session recording (rec_read.h) and prints,
 * decoded with the compiled-in descriptors, every palpation threshold
 * SessionEvent and the last Metrics sample per organ:
 *   EVENT up|down LEVEL TOOL TEXT
 *   METRICS organ=N time_above_st=.. time_above_mpf=.. time_above_sft=..
 *           contact_time=.. mean_contact_force=.. path_length=.. peak_force=..
 * Exit 1 when the file cannot be read, is damaged or a sample does not
 * decode.
 * usage: rec_palpation FILE.db */
#include <stdio.h>

#include "rec_read.h"
#include "viscera.h"

static int on_event(void *arg, const void *sample, const recfile_row_t *row) {
  (void)arg, (void)row;
  const viscera_SessionEvent *e = sample;
  if (e->kind == viscera_EVENT_THRESHOLD_CROSSED_UP || e->kind == viscera_EVENT_THRESHOLD_CROSSED_DOWN)
    printf("EVENT %s %.3f %d %s\n", e->kind == viscera_EVENT_THRESHOLD_CROSSED_UP ? "up" : "down", e->value,
           (int)e->tool_id, e->text);
  return 0;
}

enum { MAXO = 16 };
typedef struct last_metrics {
  viscera_Metrics m[MAXO]; /* plain values only: safe to keep past the callback */
  int have[MAXO];
} last_metrics_t;

static int on_metrics(void *arg, const void *sample, const recfile_row_t *row) {
  (void)row;
  last_metrics_t *l = arg;
  const viscera_Metrics *m = sample;
  if (m->organ_id < MAXO) {
    l->m[m->organ_id] = *m;
    l->have[m->organ_id] = 1;
  }
  return 0;
}

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: rec_palpation FILE.db\n");
    return 2;
  }
  recfile_t *rf = NULL;
  verr_t err;
  if (recfile_open(&rf, argv[1], &err) < 0) {
    fprintf(stderr, "rec_palpation: %s\n", err.msg);
    return 1;
  }
  static last_metrics_t last;
  int bad = rec_read_topic("rec_palpation", rf, "viscera_SessionEvent", &viscera_SessionEvent_desc, on_event, NULL);
  bad += rec_read_topic("rec_palpation", rf, "viscera_Metrics", &viscera_Metrics_desc, on_metrics, &last);
  recfile_close(rf);
  for (int i = 0; i < MAXO; i++)
    if (last.have[i])
      printf("METRICS organ=%d time_above_st=%.3f time_above_mpf=%.3f time_above_sft=%.3f contact_time=%.3f "
             "mean_contact_force=%.4f path_length=%.4f peak_force=%.4f\n",
             i, last.m[i].time_above_st, last.m[i].time_above_mpf, last.m[i].time_above_sft, last.m[i].contact_time,
             last.m[i].mean_contact_force, last.m[i].path_length, last.m[i].peak_force);
  return bad ? 1 : 0;
}
