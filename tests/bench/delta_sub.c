/* SPDX-License-Identifier: Apache-2.0 */
/* delta_sub: a light stand-in for a viewer in the load benchmark: joins a
 * seat, waits for its MeshState keyframe (a late joiner must get one at
 * once: transient-local), then takes every MeshDelta as it arrives and
 * measures delivery latency (arrival minus the server's source timestamp;
 * same machine, same clock). A delta written before it joined (kept in the
 * writer's history and handed over at the join) is counted apart, not as a
 * latency: its age is how long ago the organ last moved, not how long the
 * network took. Draws nothing, so 30 of them fit on 2 cores
 * next to 5 servers. Prints one SUB line at exit. */
#include <getopt.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "dds/vdds.h"
#include "viscera.h"
#include "vstats.h"
#include "vtime.h"

int main(int argc, char **argv) {
  static const struct option opts[] = {{"partition", required_argument, 0, 'p'},
                                       {"duration", required_argument, 0, 'd'},
                                       {"name", required_argument, 0, 'n'},
                                       {0, 0, 0, 0}};
  const char *partition = NULL, *name = "sub";
  double duration = 10;
  int c;
  while ((c = getopt_long(argc, argv, "", opts, NULL)) != -1) {
    if (c == 'p')
      partition = optarg;
    else if (c == 'd')
      duration = atof(optarg);
    else if (c == 'n')
      name = optarg;
    else
      return 2;
  }
  verr_t err;
  int domain = cli_env_domain(&err);
  vdds_t dds;
  if (domain < 0 || vdds_open(&dds, domain, partition, &err)) {
    fprintf(stderr, "delta_sub: %s\n", err.msg);
    return 1;
  }
  dds_entity_t rs = vdds_reader(&dds, VT_MESH_STATE, &err), rd = vdds_reader(&dds, VT_MESH_DELTA, &err);
  if (rs < 0 || rd < 0) {
    fprintf(stderr, "delta_sub: %s\n", err.msg);
    return 1;
  }
  dds_entity_t ws = dds_create_waitset(dds.participant);
  dds_entity_t cs = dds_create_readcondition(rs, DDS_ANY_STATE), cd = dds_create_readcondition(rd, DDS_ANY_STATE);
  dds_waitset_attach(ws, cs, 0);
  dds_waitset_attach(ws, cd, 1);
  size_t cap = 1 << 16, n = 0;
  double *lat = malloc(cap * sizeof *lat);
  uint64_t t0 = vtime_mono_ns(), keyframes = 0, deltas = 0, history = 0;
  const dds_time_t joined = dds_time();
  double first_key_ms = -1;
  while (lat && (double)(vtime_mono_ns() - t0) * 1e-9 < duration) {
    dds_waitset_wait(ws, NULL, 0, DDS_MSECS(100));
    void *samples[16] = {0};
    dds_sample_info_t infos[16];
    int k = dds_take(rs, samples, infos, 16, 16);
    for (int i = 0; i < k; i++)
      if (infos[i].valid_data && keyframes++ == 0) first_key_ms = (double)(vtime_mono_ns() - t0) * 1e-6;
    if (k > 0) dds_return_loan(rs, samples, k);
    memset(samples, 0, sizeof samples);
    k = dds_take(rd, samples, infos, 16, 16);
    dds_time_t now = dds_time();
    for (int i = 0; i < k; i++) {
      if (!infos[i].valid_data) continue;
      deltas++;
      if (infos[i].source_timestamp < joined) {
        history++;
        continue;
      }
      if (n == cap) {
        double *more = realloc(lat, 2 * cap * sizeof *lat);
        if (!more) break;
        lat = more, cap *= 2;
      }
      lat[n++] = (double)(now - infos[i].source_timestamp) * 1e-3;
    }
    if (k > 0) dds_return_loan(rd, samples, k);
  }
  vstats_summary_t st = vstats_summarise(lat, n);
  printf("SUB name=%s keyframes=%" PRIu64 " first_keyframe_ms=%.1f deltas=%" PRIu64
         " latency_us_median=%.1f latency_us_p99=%.1f latency_us_max=%.1f history=%" PRIu64 "\n",
         name, keyframes, first_key_ms, deltas, st.median, st.p99, st.max, history);
  free(lat);
  vdds_close(&dds);
  return keyframes > 0 ? 0 : 3;
}
