/* SPDX-License-Identifier: Apache-2.0 */
/* keyframe_wait: a late joiner that measures how long its first MeshState
 * keyframe takes once the server's writer is matched (issue 14: a keyframe
 * must survive a lossy link). Subscribes to MeshState and MeshDelta of one
 * partition, like a viewer, and prints at exit:
 *   KEYFRAME matched_ms=M keyframe_ms=K wait_ms=K-M keyframe_bytes=B deltas=N delta_bytes=D
 * (times from start; -1 = never; bytes = payload of the samples: positions,
 * triangles, indices, dq). Exit 0 when a keyframe arrived, 3 when not, 1 on a
 * DDS error. usage: keyframe_wait --partition P [--duration S] (domain:
 * $VISCERA_DOMAIN). */
#include <getopt.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "dds/vdds.h"
#include "viscera.h"
#include "vtime.h"

typedef struct counts {
  double matched_ms, key_ms;
  uint64_t key_bytes, deltas, delta_bytes;
} counts_t;

static void poll_once(dds_entity_t rs, dds_entity_t rd, uint64_t t0, counts_t *c) {
  dds_subscription_matched_status_t ms;
  if (c->matched_ms < 0 && dds_get_subscription_matched_status(rs, &ms) == 0 && ms.current_count > 0)
    c->matched_ms = (double)(vtime_mono_ns() - t0) * 1e-6;
  void *samples[16] = {0};
  dds_sample_info_t infos[16];
  int k = dds_take(rs, samples, infos, 16, 16);
  for (int i = 0; i < k; i++) {
    if (!infos[i].valid_data) continue;
    const viscera_MeshState *s = samples[i];
    if (c->key_ms < 0) c->key_ms = (double)(vtime_mono_ns() - t0) * 1e-6;
    c->key_bytes = (uint64_t)s->positions._length * 4 + (uint64_t)s->triangles._length * 4;
  }
  if (k > 0) dds_return_loan(rs, samples, k);
  memset(samples, 0, sizeof samples);
  k = dds_take(rd, samples, infos, 16, 16);
  for (int i = 0; i < k; i++) {
    if (!infos[i].valid_data) continue;
    const viscera_MeshDelta *d = samples[i];
    c->deltas++;
    c->delta_bytes += (uint64_t)d->indices._length * 4 + (uint64_t)d->dq._length * 2;
  }
  if (k > 0) dds_return_loan(rd, samples, k);
}

int main(int argc, char **argv) {
  static const struct option opts[] = {
      {"partition", required_argument, 0, 'p'}, {"duration", required_argument, 0, 'd'}, {0, 0, 0, 0}};
  const char *partition = NULL;
  double duration = 10;
  for (int c; (c = getopt_long(argc, argv, "", opts, NULL)) != -1;) {
    if (c == 'p')
      partition = optarg;
    else if (c == 'd')
      duration = atof(optarg);
    else
      return 2;
  }
  verr_t err;
  int domain = cli_env_domain(&err);
  vdds_t dds;
  if (domain < 0 || vdds_open(&dds, domain, partition, &err)) {
    fprintf(stderr, "keyframe_wait: %s\n", err.msg);
    return 1;
  }
  dds_entity_t rs = vdds_reader(&dds, VT_MESH_STATE, &err), rd = rs < 0 ? rs : vdds_reader(&dds, VT_MESH_DELTA, &err);
  if (rs < 0 || rd < 0) {
    fprintf(stderr, "keyframe_wait: %s\n", err.msg);
    return 1;
  }
  counts_t c = {.matched_ms = -1, .key_ms = -1};
  uint64_t t0 = vtime_mono_ns();
  while ((double)(vtime_mono_ns() - t0) * 1e-9 < duration) {
    poll_once(rs, rd, t0, &c);
    dds_sleepfor(DDS_MSECS(1));
  }
  printf("KEYFRAME matched_ms=%.1f keyframe_ms=%.1f wait_ms=%.1f keyframe_bytes=%" PRIu64 " deltas=%" PRIu64
         " delta_bytes=%" PRIu64 "\n",
         c.matched_ms, c.key_ms, c.key_ms >= 0 && c.matched_ms >= 0 ? c.key_ms - c.matched_ms : -1.0, c.key_bytes,
         c.deltas, c.delta_bytes);
  vdds_close(&dds);
  return c.key_ms >= 0 ? 0 : 3;
}
