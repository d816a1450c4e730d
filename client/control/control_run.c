/* SPDX-License-Identifier: Apache-2.0 */
#include "control_run.h"

#include "control_deliver.h"

#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include "dds/seat_server.h"
#include "dds/vdds.h"
#include "dds/vdds_config.h"
#include "dds/vdds_gate.h"
#include "vtime.h"

int control_run(const control_options_t *o) {
  verr_t err;
  vdds_t dds;
  if (vdds_open(&dds, o->domain, o->partition, &err)) {
    fprintf(stderr, "viscera-control: %s\n", err.msg);
    return 2;
  }
  int rc = 2;
  control_deliver_t deliver = {0}; /* closed at out: whatever was opened */
  /* The answer is believed from the seat's server only (seat_server.h,
   * issue 15.2); its events are source 0, the only key let in. */
  seat_server_t server;
  vdds_gate_t gate;
  vdds_gate_init(&gate, 1, NULL, NULL);
  uint64_t ignored = 0;
  if (seat_server_open(&server, dds.participant, &err)) {
    fprintf(stderr, "viscera-control: %s\n", err.msg);
    vdds_close(&dds);
    vdds_gate_destroy(&gate);
    return 2;
  }
  dds_entity_t w = vdds_writer(&dds, VT_SESSION_CONTROL, &err);
  dds_entity_t r = vdds_reader_gated(&dds, VT_SESSION_EVENT, &gate, 0, 1, NULL, &err);
  if (w < 0 || r < 0) {
    fprintf(stderr, "viscera-control: %s (is this identity allowed to send SessionControl in this partition?)\n",
            err.msg);
    goto out;
  }
  const char *part = o->partition ? o->partition : VDDS_DEFAULT_PARTITION;
  if (control_deliver_open(&deliver, dds.participant, w, part) < 0) {
    fprintf(stderr, "viscera-control: DDS: cannot read the subscriptions\n");
    goto out;
  }
  /* The server is there once its SceneInfo (transient-local) arrives. A
   * matched writer alone proves nothing: a recorder's reader matches too. */
  dds_entity_t r_scene = vdds_reader(&dds, VT_SCENE_INFO, &err);
  if (r_scene < 0) {
    fprintf(stderr, "viscera-control: %s\n", err.msg);
    goto out;
  }
  uint64_t start = vtime_mono_ns(), deadline = start + (uint64_t)(o->wait_s * 1e9);
  int have_server = 0, told = 0;
  while (!have_server && vtime_mono_ns() < deadline) {
    if (vdds_nothing_seen_due(&told, vdds_matched_writers(r_scene), start, vtime_mono_ns()))
      vdds_explain_nothing_seen(stderr, "viscera-control", "no server found", o->domain, part, VDDS_NOTHING_SEEN_S);
    void *samples[1] = {0};
    dds_sample_info_t info;
    int n = dds_take(r_scene, samples, &info, 1, 1);
    if (n > 0) {
      have_server = info.valid_data && seat_server_scene(&server, r_scene, &info, samples[0]);
      dds_return_loan(r_scene, samples, n);
    } else {
      dds_sleepfor(DDS_MSECS(20));
    }
  }
  if (!have_server) {
    fprintf(stderr, "viscera-control: no server on domain %d partition '%s' within %.1f s\n", o->domain, part,
            o->wait_s);
    if (!told) /* a --wait shorter than VDDS_NOTHING_SEEN_S: explain now */
      vdds_explain_nothing_seen(stderr, "viscera-control", "no server found", o->domain, part, o->wait_s);
    rc = 1;
    goto out;
  }
  rc = 1;
  char mine[64];
  snprintf(mine, sizeof mine, "[station %" PRIu32 " seq %" PRIu64 "]", o->cmd.source_id, o->cmd.seq);
  uint64_t next_send = 0;
  while (vtime_mono_ns() < deadline) {
    /* Resent (same seq, the server drops copies) until answered: the
     * server's reader may match this writer a little after its SceneInfo
     * arrived, and a volatile write before that reaches nobody. */
    if (vtime_mono_ns() >= next_send) {
      if (dds_write(w, &o->cmd) < 0) {
        fprintf(stderr, "viscera-control: write failed\n");
        rc = 2;
        break;
      }
      control_deliver_wrote(&deliver);
      next_send = vtime_mono_ns() + 500000000ull;
    }
    void *samples[8] = {0};
    dds_sample_info_t infos[8];
    int n = dds_take(r, samples, infos, 8, 8);
    for (int i = 0; i < n; i++) {
      const viscera_SessionEvent *e = samples[i];
      if (!infos[i].valid_data) continue;
      seat_verdict_t v = seat_server_from(&server, r, infos[i].publication_handle);
      if (v != SEAT_FROM_SERVER) {
        if (v == SEAT_NOT_SERVER) vdds_gate_block(&gate, infos[i].publication_handle, VDDS_GATE_ANY_KEY);
        ignored++;
        continue;
      }
      if (!strstr(e->text, mine)) continue;
      if (e->kind == viscera_EVENT_CONTROL_APPLIED && rc == 1) {
        printf("applied: %s\n", e->text);
        rc = 0;
      } else if (e->kind == viscera_EVENT_INPUT_REJECTED && rc == 1) {
        printf("refused: %s\n", e->text);
        rc = 3;
      }
    }
    if (n > 0) dds_return_loan(r, samples, n);
    if (rc != 1) break;
    dds_sleepfor(DDS_MSECS(10));
  }
  if (rc == 0 || rc == 3) { /* answered: the seat's other readers (a recorder) get it too */
    int missing = 0;
    if (control_deliver_finish(&deliver, &o->cmd, 0.3, 2.0, &missing))
      fprintf(stderr,
              "viscera-control: %d other reader(s) of SessionControl in '%s' (a recorder?) not reached within 2 s; "
              "the server has the command\n",
              missing, part);
  }
  if (rc == 1) fprintf(stderr, "viscera-control: no answer from the server within %.1f s\n", o->wait_s);
  if (rc == 3) rc = 1;
  if (ignored)
    fprintf(stderr, "viscera-control: %" PRIu64 " SessionEvent samples ignored: not from the seat's server\n", ignored);
out:
  control_deliver_close(&deliver);
  vdds_close(&dds);
  seat_server_close(&server);
  vdds_gate_destroy(&gate);
  return rc;
}
