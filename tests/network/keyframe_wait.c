/* SPDX-License-Identifier: Apache-2.0 */
/* keyframe_wait: a late joiner that measures how long its first keyframe
 * takes once the server's writer is matched (issue 14: a keyframe must
 * survive a lossy link). Subscribes to MeshDelta and, by --path, to
 * MeshState (state: a viewer before keyframe chunks), MeshKeyChunk
 * (chunks: a transient-local and a volatile reader, as the viewer) or both
 * (both: today's viewer, the default), and prints at exit:
 *   KEYFRAME matched_ms=M keyframe_ms=K wait_ms=K-M keyframe_bytes=B deltas=N delta_bytes=D
 *            state_ms=S chunks_ms=C chunks=N chunk_bytes=E path=P
 * (times from start; K the first keyframe by either path, S by MeshState,
 * C the first complete, sound chunk set, decoded; -1 = never; bytes =
 * payload of the samples: positions, triangles, indices, dq, encoded
 * keyframe). Exit 0 when a keyframe arrived, 3 when not, 1 on a DDS error
 * or a refused chunk. usage: keyframe_wait --partition P [--duration S]
 * [--path state|chunks|both] (domain: $VISCERA_DOMAIN). */
#include <getopt.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "dds/key_chunks.h"
#include "dds/vdds.h"
#include "viscera.h"
#include "vtime.h"

typedef struct counts {
  double matched_ms, key_ms, state_ms, chunks_ms;
  uint64_t key_bytes, deltas, delta_bytes, chunks, chunk_bytes, refused;
  key_assembly_t asm_[viscera_MAX_ORGANS];
} counts_t;

static double since(uint64_t t0) { return (double)(vtime_mono_ns() - t0) * 1e-6; }

static void take_chunks(dds_entity_t rc, uint64_t t0, counts_t *c) {
  void *samples[16] = {0};
  dds_sample_info_t infos[16];
  int k = dds_take(rc, samples, infos, 16, 16);
  for (int i = 0; i < k; i++) {
    if (!infos[i].valid_data) continue;
    key_chunk_t ch;
    key_chunk_from_wire(samples[i], &ch);
    c->chunks++;
    verr_t err;
    if (ch.organ_id >= viscera_MAX_ORGANS) {
      fprintf(stderr, "keyframe_wait: chunk slot %u: organ %u out of range\n", ch.slot, ch.organ_id);
      c->refused++;
      continue;
    }
    key_assembly_t *a = &c->asm_[ch.organ_id];
    int r = key_assembly_add(a, &ch, viscera_MAX_ORGANS, &err);
    if (r < 0) {
      fprintf(stderr, "keyframe_wait: chunk slot %u: %s\n", ch.slot, err.msg);
      c->refused++;
    }
    if (r <= 0) continue;
    float *pos;
    uint32_t *tris;
    size_t nv, nt;
    if (key_decode(a->buf, a->total_bytes, &pos, &nv, &tris, &nt, &err)) {
      fprintf(stderr, "keyframe_wait: organ %u: %s\n", ch.organ_id, err.msg);
      c->refused++;
      continue;
    }
    free(pos);
    free(tris);
    if (c->chunks_ms < 0) c->chunks_ms = since(t0);
    if (c->key_ms < 0) c->key_ms = c->chunks_ms;
    c->chunk_bytes = a->total_bytes;
  }
  if (k > 0) dds_return_loan(rc, samples, k);
}

static void poll_once(dds_entity_t rs, dds_entity_t rd, dds_entity_t rc, dds_entity_t rl, uint64_t t0, counts_t *c) {
  /* Matched: the first keyframe reader (of the paths asked for) that sees the server's writer. */
  dds_subscription_matched_status_t ms;
  if (c->matched_ms < 0 && ((rs > 0 && dds_get_subscription_matched_status(rs, &ms) == 0 && ms.current_count > 0) ||
                            (rc > 0 && dds_get_subscription_matched_status(rc, &ms) == 0 && ms.current_count > 0)))
    c->matched_ms = since(t0);
  void *samples[16] = {0};
  dds_sample_info_t infos[16];
  int k = rs > 0 ? dds_take(rs, samples, infos, 16, 16) : 0;
  for (int i = 0; i < k; i++) {
    if (!infos[i].valid_data) continue;
    const viscera_MeshState *s = samples[i];
    if (c->state_ms < 0) c->state_ms = since(t0);
    if (c->key_ms < 0) c->key_ms = c->state_ms;
    c->key_bytes = (uint64_t)s->positions._length * 4 + (uint64_t)s->triangles._length * 4;
  }
  if (k > 0) dds_return_loan(rs, samples, k);
  if (rl > 0) take_chunks(rl, t0, c);
  if (rc > 0) take_chunks(rc, t0, c);
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
  static const struct option opts[] = {{"partition", required_argument, 0, 'p'},
                                       {"duration", required_argument, 0, 'd'},
                                       {"path", required_argument, 0, 'k'},
                                       {0, 0, 0, 0}};
  const char *partition = NULL, *path = "both";
  double duration = 10;
  for (int c; (c = getopt_long(argc, argv, "", opts, NULL)) != -1;) {
    if (c == 'p')
      partition = optarg;
    else if (c == 'd')
      duration = atof(optarg);
    else if (c == 'k' && (!strcmp(optarg, "state") || !strcmp(optarg, "chunks") || !strcmp(optarg, "both")))
      path = optarg;
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
  /* Readers are created before use only for the paths asked for: a reader
   * not created is not matched, so the link carries nothing for it. */
  int want_state = strcmp(path, "chunks") != 0, want_chunks = strcmp(path, "state") != 0;
  dds_entity_t rd = vdds_reader(&dds, VT_MESH_DELTA, &err);
  dds_entity_t rs = rd < 0 || !want_state ? 0 : vdds_reader(&dds, VT_MESH_STATE, &err);
  /* Chunks as the viewer takes them (view/scene_view.c): a transient-local
   * reader and a volatile one for the set the server writes again. */
  dds_entity_t rc = 0, rl = 0;
  for (int live = 0; live < 2 && rd >= 0 && rs >= 0 && want_chunks; live++) {
    dds_qos_t *q = vdds_topic_qos(VT_MESH_KEY_CHUNK);
    if (live) dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
    *(live ? &rl : &rc) = dds_create_reader(dds.subscriber, dds.topics[VT_MESH_KEY_CHUNK], q, NULL);
    dds_delete_qos(q);
  }
  if (rs < 0 || rd < 0 || rc < 0 || rl < 0) {
    fprintf(stderr, "keyframe_wait: %s\n", err.msg);
    return 1;
  }
  static counts_t c;
  c.matched_ms = c.key_ms = c.state_ms = c.chunks_ms = -1;
  uint64_t t0 = vtime_mono_ns();
  while ((double)(vtime_mono_ns() - t0) * 1e-9 < duration) {
    poll_once(rs, rd, rc, rl, t0, &c);
    dds_sleepfor(DDS_MSECS(1));
  }
  printf("KEYFRAME matched_ms=%.1f keyframe_ms=%.1f wait_ms=%.1f keyframe_bytes=%" PRIu64 " deltas=%" PRIu64
         " delta_bytes=%" PRIu64 " state_ms=%.1f chunks_ms=%.1f chunks=%" PRIu64 " chunk_bytes=%" PRIu64 " path=%s\n",
         c.matched_ms, c.key_ms, c.key_ms >= 0 && c.matched_ms >= 0 ? c.key_ms - c.matched_ms : -1.0, c.key_bytes,
         c.deltas, c.delta_bytes, c.state_ms, c.chunks_ms, c.chunks, c.chunk_bytes, path);
  vdds_close(&dds);
  for (int i = 0; i < viscera_MAX_ORGANS; i++) key_assembly_free(&c.asm_[i]);
  return c.refused ? 1 : c.key_ms >= 0 ? 0 : 3;
}
