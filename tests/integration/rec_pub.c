/* SPDX-License-Identifier: Apache-2.0 */
/* rec_pub: the publisher side of the recorder integration test.
 *
 * Publishes, through the product's own vdds setup and types:
 *   1. a MeshState keyframe for organs 0 and 1 (transient-local), then
 *      touches the --ready file so the driver starts the recorder only
 *      after the keyframes exist: the recorder must get them as a late
 *      joiner;
 *   2. once the recorder's readers have matched, --tools ToolCommand
 *      samples at --rate Hz (values from rec_values.h) with a MeshDelta
 *      for organ (k % 2) after every 25th;
 *   3. a dispose of MeshDelta organ 1;
 * then waits for the reliable writers' acknowledgements and exits.
 * With --untyped it also writes a topic whose writer announces no XTypes
 * type information (a non-XTypes DDS, or an old Cyclone): the recorder
 * cannot resolve its type and must say so and record the rest. */
#include <dds/ddsc/dds_opcodes.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "dds/vdds.h"
#include "rec_values.h"
#include "viscera.h"
#include "vtime.h"

#define UNTYPED_TOPIC "rectest_Untyped"

/* ToolCommand's layout under another type name, without the XTypes type
 * information and mapping, so discovery carries no type for it. */
static dds_entity_t untyped_writer(vdds_t *v) {
  const dds_topic_descriptor_t *d = &viscera_ToolCommand_desc;
  static dds_topic_descriptor_t untyped;
  dds_topic_descriptor_t tmp = {d->m_size,  d->m_align,         d->m_flagset & ~DDS_TOPIC_XTYPES_METADATA,
                                d->m_nkeys, "rectest::Untyped", d->m_keys,
                                d->m_nops,  d->m_ops,           d->m_meta,
                                {NULL, 0},  {NULL, 0},          d->restrict_data_representation};
  memcpy(&untyped, &tmp, sizeof untyped);
  dds_entity_t t = dds_create_topic(v->participant, &untyped, UNTYPED_TOPIC, NULL, NULL);
  if (t < 0) return t;
  dds_qos_t *q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_entity_t w = dds_create_writer(v->publisher, t, q, NULL);
  dds_delete_qos(q);
  return w;
}

static int wait_matched(dds_entity_t w, const char *what, double timeout_s) {
  uint64_t end = vtime_mono_ns() + (uint64_t)(timeout_s * 1e9);
  for (;;) {
    dds_publication_matched_status_t st;
    if (dds_get_publication_matched_status(w, &st) == DDS_RETCODE_OK && st.current_count > 0) return 0;
    if (vtime_mono_ns() > end) {
      fprintf(stderr, "rec_pub: no reader matched %s within %.0f s\n", what, timeout_s);
      return -1;
    }
    dds_sleepfor(DDS_MSECS(10));
  }
}

int main(int argc, char **argv) {
  int domain = 41;
  const char *partition = "viscera/rectest";
  const char *ready = NULL;
  long tools = 500, deltas_every = 25;
  double rate = 2000;
  int untyped = 0;
  static const struct option longopts[] = {
      {"domain", required_argument, 0, 'd'},
      {"partition", required_argument, 0, 'p'},
      {"ready", required_argument, 0, 'r'},
      {"tools", required_argument, 0, 'n'},
      {"rate", required_argument, 0, 'z'},
      {"untyped", no_argument, 0, 'u'},
      {0, 0, 0, 0},
  };
  int c;
  while ((c = getopt_long(argc, argv, "d:p:r:n:z:u", longopts, NULL)) != -1) {
    switch (c) {
    case 'd':
      domain = cli_parse_domain(optarg);
      break;
    case 'p':
      partition = optarg;
      break;
    case 'r':
      ready = optarg;
      break;
    case 'n':
      tools = atol(optarg);
      break;
    case 'z':
      rate = atof(optarg);
      break;
    case 'u':
      untyped = 1;
      break;
    default:
      fprintf(stderr,
              "usage: rec_pub [--domain N] [--partition P] [--ready FILE] [--tools N] [--rate HZ] [--untyped]\n");
      return 2;
    }
  }
  if (domain < 0 || tools < 0 || rate <= 0) {
    fprintf(stderr, "rec_pub: bad arguments\n");
    return 2;
  }

  verr_t err = {{0}};
  vdds_t v;
  if (vdds_open(&v, (dds_domainid_t)domain, partition, &err) < 0) {
    fprintf(stderr, "rec_pub: %s\n", err.msg);
    return 1;
  }
  int status = 1;
  dds_entity_t w_state = vdds_writer(&v, VT_MESH_STATE, &err);
  dds_entity_t w_delta = vdds_writer(&v, VT_MESH_DELTA, &err);
  dds_entity_t w_tool = vdds_writer(&v, VT_TOOL_COMMAND, &err);
  if (w_state < 0 || w_delta < 0 || w_tool < 0) {
    fprintf(stderr, "rec_pub: %s\n", err.msg);
    goto out;
  }
  dds_entity_t w_untyped = 0;
  if (untyped && (w_untyped = untyped_writer(&v)) < 0) {
    fprintf(stderr, "rec_pub: cannot create the untyped writer: %s\n", dds_strretcode(w_untyped));
    goto out;
  }

  /* 1. keyframes before anyone listens */
  float pos[3 * REC_TEST_KEYFRAME_VERTICES];
  uint32_t tri[3 * (REC_TEST_KEYFRAME_VERTICES - 2)];
  for (uint32_t i = 0; i < 3 * REC_TEST_KEYFRAME_VERTICES; i++) pos[i] = 0.001f * (float)i;
  for (uint32_t t = 0; t < REC_TEST_KEYFRAME_VERTICES - 2; t++) {
    tri[3 * t] = t;
    tri[3 * t + 1] = t + 1;
    tri[3 * t + 2] = t + 2;
  }
  for (uint32_t organ = 0; organ < 2; organ++) {
    viscera_MeshState ks = {.organ_id = organ, .topology_version = 1, .keyframe_seq = 1, .sim_time_ns = 0};
    ks.positions = (dds_sequence_float){3 * REC_TEST_KEYFRAME_VERTICES, 3 * REC_TEST_KEYFRAME_VERTICES, pos, false};
    ks.triangles = (dds_sequence_unsigned_long){3 * (REC_TEST_KEYFRAME_VERTICES - 2),
                                                3 * (REC_TEST_KEYFRAME_VERTICES - 2), tri, false};
    if (dds_write(w_state, &ks) < 0) {
      fprintf(stderr, "rec_pub: keyframe write failed\n");
      goto out;
    }
  }
  if (ready) {
    FILE *f = fopen(ready, "w");
    if (!f) {
      fprintf(stderr, "rec_pub: cannot create %s\n", ready);
      goto out;
    }
    fclose(f);
  }
  fprintf(stderr, "rec_pub: keyframes written, waiting for the recorder\n");

  /* 2. stream once the recorder listens: volatile best-effort samples
   * written before its readers exist would be lost by design */
  if (wait_matched(w_tool, "ToolCommand", 30) < 0 || wait_matched(w_delta, "MeshDelta", 30) < 0 ||
      wait_matched(w_state, "MeshState", 30) < 0)
    goto out;
  const uint64_t period = (uint64_t)(1e9 / rate);
  uint64_t next = vtime_mono_ns();
  uint32_t frame = 0;
  uint32_t idx[4] = {1, 5, 9, 77};
  int16_t dq[12];
  for (long i = 0; i < tools; i++) {
    viscera_ToolCommand tc = rec_test_tool_command((uint32_t)i);
    if (dds_write(w_tool, &tc) < 0) {
      fprintf(stderr, "rec_pub: ToolCommand write failed\n");
      goto out;
    }
    if (w_untyped > 0 && i % 50 == 0 && dds_write(w_untyped, &tc) < 0) {
      fprintf(stderr, "rec_pub: untyped write failed\n");
      goto out;
    }
    if ((i + 1) % deltas_every == 0) {
      for (int k = 0; k < 12; k++) dq[k] = (int16_t)(k - 6 + (int)frame);
      viscera_MeshDelta d = {.organ_id = frame % 2,
                             .topology_version = 1,
                             .keyframe_seq = 1,
                             .frame_seq = frame,
                             .sim_time_ns = 1000000ull * frame,
                             .quant_step = 1e-5f};
      d.indices = (dds_sequence_unsigned_long){4, 4, idx, false};
      d.dq = (dds_sequence_short){12, 12, dq, false};
      if (dds_write(w_delta, &d) < 0) {
        fprintf(stderr, "rec_pub: MeshDelta write failed\n");
        goto out;
      }
      frame++;
    }
    next += period;
    vtime_sleep_until(next);
  }

  /* 3. one instance ends */
  viscera_MeshDelta gone = {.organ_id = REC_TEST_DISPOSED_ORGAN};
  if (dds_dispose(w_delta, &gone) < 0) {
    fprintf(stderr, "rec_pub: dispose failed\n");
    goto out;
  }
  if (dds_wait_for_acks(w_delta, DDS_SECS(5)) < 0 || dds_wait_for_acks(w_state, DDS_SECS(5)) < 0)
    fprintf(stderr, "rec_pub: warning: reliable writers not acknowledged within 5 s\n");
  /* best-effort ToolCommands have no acknowledgement: give them a moment */
  dds_sleepfor(DDS_MSECS(200));
  fprintf(stderr, "rec_pub: published %ld ToolCommand, %u MeshDelta, 2 MeshState, 1 dispose\n", tools, frame);
  printf("PUB tools=%ld deltas=%u\n", tools, frame);
  status = 0;
out:
  vdds_close(&v);
  return status;
}
