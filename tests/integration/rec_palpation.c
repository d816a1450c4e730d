/* SPDX-License-Identifier: Apache-2.0 */
/* rec_palpation: the checker of the palpation_thresholds integration test.
 * Reads a session recording of the default scene (rec_read.h: every sample
 * decoded with the compiled-in descriptors) and asserts, for the scripted
 * 8 mm press of the probe (thresholds st 0.5, mpf 0.8, sft 1.5 N; about
 * 0.97 N held):
 *  - SessionEvents: at least one upward and one downward crossing of ST
 *    and of MPF, none upward of SFT; an upward ST crossing of tool 0 whose
 *    text names ST ("ST crossed up...");
 *  - the last Metrics of organ 0: time above ST and MPF > 0 with ST >= MPF,
 *    none above SFT, contact time >= time above ST and < 3 s, mean contact
 *    force in (0.3 N, peak), peak in (0.8 N, 1.5 N), path length (2 x 4.3 cm
 *    down and up) in (0.07 m, 0.12 m). Times are simulated time, which runs
 *    slower than the wall when the server cannot keep real time (a sanitizer
 *    build on a loaded machine), so only their order is asserted;
 *  - the server's own tracker, as its last ToolMetrics of the probe,
 *    agrees: time above ST > 0 and >= the Metrics' (the same figure the
 *    server prints as its PALPATION summary).
 * Prints the events and figures it read, then one line per failed check.
 * Exit 0 when every check holds, 1 otherwise (also when the file cannot be
 * read, is damaged or a sample does not decode).
 *
 * With --expect-undecodable TOPIC N it checks a deliberately damaged copy
 * instead: reading TOPIC must meet exactly N undecodable samples (reported
 * on stderr by rec_read, naming the topic) and the other topics none.
 * usage: rec_palpation [--expect-undecodable TOPIC N] FILE.db */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rec_read.h"
#include "viscera.h"

enum { MAXO = 16, MAXT = 8 };

typedef struct palp {
  int up[3], down[3];      /* crossings of ST, MPF, SFT */
  int st_text_ok;          /* an upward ST crossing of tool 0 whose text names ST */
  viscera_Metrics m[MAXO]; /* plain values only: safe to keep past the callback */
  int have[MAXO];
  double tool_st[MAXT]; /* last ToolMetrics time_above_st per tool */
  char tool_name[MAXT][65];
  int have_tool[MAXT];
} palp_t;

static const double LEVEL[3] = {0.5, 0.8, 1.5};

static int on_event(void *arg, const void *sample, const recfile_row_t *row) {
  (void)row;
  palp_t *p = arg;
  const viscera_SessionEvent *e = sample;
  int up = e->kind == viscera_EVENT_THRESHOLD_CROSSED_UP;
  if (!up && e->kind != viscera_EVENT_THRESHOLD_CROSSED_DOWN) return 0;
  printf("EVENT %s %.3f %d %s\n", up ? "up" : "down", e->value, (int)e->tool_id, e->text);
  for (int k = 0; k < 3; k++)
    if (fabs(e->value - LEVEL[k]) < 5e-4) (up ? p->up : p->down)[k]++;
  if (up && fabs(e->value - LEVEL[0]) < 5e-4 && e->tool_id == 0 && !strncmp(e->text, "ST crossed up", 13))
    p->st_text_ok = 1;
  return 0;
}

static int on_metrics(void *arg, const void *sample, const recfile_row_t *row) {
  (void)row;
  palp_t *p = arg;
  const viscera_Metrics *m = sample;
  if (m->organ_id < MAXO) {
    p->m[m->organ_id] = *m;
    p->have[m->organ_id] = 1;
  }
  return 0;
}

static int on_tool_metrics(void *arg, const void *sample, const recfile_row_t *row) {
  (void)row;
  palp_t *p = arg;
  const viscera_ToolMetrics *m = sample;
  if (m->tool_id < MAXT) {
    p->tool_st[m->tool_id] = m->time_above_st;
    snprintf(p->tool_name[m->tool_id], sizeof p->tool_name[0], "%s", m->name);
    p->have_tool[m->tool_id] = 1;
  }
  return 0;
}

static int failures;
#define EXPECT(cond, ...)                                                                                              \
  do {                                                                                                                 \
    if (!(cond)) {                                                                                                     \
      failures++;                                                                                                      \
      printf("FAIL: ");                                                                                                \
      printf(__VA_ARGS__);                                                                                             \
      printf(" (%s)\n", #cond);                                                                                        \
    }                                                                                                                  \
  } while (0)

static void check_session(const palp_t *p) {
  EXPECT(p->up[0] >= 1, "no upward ST crossing in the recording");
  EXPECT(p->down[0] >= 1, "no downward ST crossing in the recording");
  EXPECT(p->up[1] >= 1, "no upward MPF crossing in the recording");
  EXPECT(p->down[1] >= 1, "no downward MPF crossing in the recording");
  EXPECT(p->up[2] == 0, "SFT crossed: the scripted press should stay below it");
  EXPECT(p->st_text_ok, "event text does not name ST");
  EXPECT(p->have[0], "no Metrics in the recording");
  if (!p->have[0]) return;
  const viscera_Metrics *m = &p->m[0];
  double st = m->time_above_st, mpf = m->time_above_mpf, sft = m->time_above_sft, ct = m->contact_time,
         mf = m->mean_contact_force, pl = m->path_length, pk = m->peak_force;
  printf("METRICS organ=0 time_above_st=%.3f time_above_mpf=%.3f time_above_sft=%.3f contact_time=%.3f "
         "mean_contact_force=%.4f path_length=%.4f peak_force=%.4f\n",
         st, mpf, sft, ct, mf, pl, pk);
  EXPECT(st > 0 && mpf > 0 && st >= mpf, "Metrics: time above ST %.3f, MPF %.3f", st, mpf);
  EXPECT(ct >= st && ct < 3, "Metrics: contact time %.3f", ct);
  EXPECT(sft == 0, "Metrics: time above SFT %.3f", sft);
  EXPECT(mf > 0.3 && mf < pk, "Metrics: mean contact force %.4f (peak %.4f)", mf, pk);
  EXPECT(pk > 0.8 && pk < 1.5, "Metrics: peak force %.4f", pk);
  EXPECT(pl > 0.07 && pl < 0.12, "Metrics: path length %.4f", pl);
  int probe = -1;
  for (int t = 0; t < MAXT; t++)
    if (p->have_tool[t] && !strcmp(p->tool_name[t], "probe")) probe = t;
  EXPECT(probe >= 0, "no ToolMetrics of the probe in the recording");
  if (probe < 0) return;
  printf("TOOLMETRICS tool=probe time_above_st=%.3f\n", p->tool_st[probe]);
  EXPECT(p->tool_st[probe] > 0 && p->tool_st[probe] >= st, "server's time above ST %.3f vs Metrics %.3f",
         p->tool_st[probe], st);
}

int main(int argc, char **argv) {
  const char *bad_topic = NULL;
  long bad_n = 0;
  if (argc == 5 && !strcmp(argv[1], "--expect-undecodable")) {
    bad_topic = argv[2];
    bad_n = strtol(argv[3], NULL, 10);
    argv += 3;
    argc -= 3;
  }
  if (argc != 2) {
    fprintf(stderr, "usage: rec_palpation [--expect-undecodable TOPIC N] FILE.db\n");
    return 2;
  }
  recfile_t *rf = NULL;
  verr_t err;
  if (recfile_open(&rf, argv[1], &err) < 0) {
    fprintf(stderr, "rec_palpation: %s\n", err.msg);
    return 1;
  }
  static palp_t p;
  static const struct {
    const char *topic;
    const dds_topic_descriptor_t *desc;
    rec_decode_cb cb;
  } T[] = {{"viscera_SessionEvent", &viscera_SessionEvent_desc, on_event},
           {"viscera_Metrics", &viscera_Metrics_desc, on_metrics},
           {"viscera_ToolMetrics", &viscera_ToolMetrics_desc, on_tool_metrics}};
  int bad = 0;
  for (size_t i = 0; i < sizeof T / sizeof T[0]; i++) {
    int n = rec_read_topic("rec_palpation", rf, T[i].topic, T[i].desc, T[i].cb, &p);
    if (bad_topic) EXPECT(n == (!strcmp(T[i].topic, bad_topic) ? bad_n : 0), "%s: %d problem(s) met", T[i].topic, n);
    bad += n;
  }
  recfile_close(rf);
  if (!bad_topic) {
    EXPECT(bad == 0, "the recording did not read completely");
    check_session(&p);
  }
  if (failures) printf("rec_palpation: %d check(s) failed\n", failures);
  return failures ? 1 : 0;
}
