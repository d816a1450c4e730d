/* SPDX-License-Identifier: Apache-2.0 */
#include "dds/key_chunks.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <dds/dds.h>
#include <zlib.h>

#include "sha256.h"
#include "viscera.h"

#define MAGIC "VKC1"
#define HEADER 16 /* magic, nverts, ntris, body length */

static void put32(uint8_t *p, uint32_t v) {
  for (int i = 0; i < 4; i++) p[i] = (uint8_t)(v >> (8 * i));
}

static uint32_t get32(const uint8_t *p) {
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

void key_digest(const uint8_t *data, size_t len, uint8_t out[KEY_DIGEST_LEN]) {
  char hex[SHA256_HEX_LEN];
  sha256_hex(data, len, hex);
  for (int i = 0; i < KEY_DIGEST_LEN; i++) {
    unsigned hi = (unsigned)(hex[2 * i] <= '9' ? hex[2 * i] - '0' : hex[2 * i] - 'a' + 10);
    unsigned lo = (unsigned)(hex[2 * i + 1] <= '9' ? hex[2 * i + 1] - '0' : hex[2 * i + 1] - 'a' + 10);
    out[i] = (uint8_t)(hi << 4 | lo);
  }
}

uint32_t key_chunk_count(size_t len) {
  if (len == 0 || len > KEY_BLOB_MAX) return 0;
  return (uint32_t)((len + KEY_CHUNK_DATA_MAX - 1) / KEY_CHUNK_DATA_MAX);
}

/* The body before deflate: planes of position deltas, then varints. */
static size_t body_bound(size_t nverts, size_t ntris) { return 12 * nverts + 15 * ntris; }

static size_t make_body(const float *pos, size_t nverts, const uint32_t *tris, size_t ntris, uint8_t *b) {
  size_t nv = 3 * nverts;
  uint32_t prev[3] = {0, 0, 0};
  for (size_t i = 0; i < nv; i++) {
    uint32_t u;
    memcpy(&u, &pos[i], 4);
    uint32_t d = u - prev[i % 3];
    prev[i % 3] = u;
    for (int k = 0; k < 4; k++) b[(size_t)k * nv + i] = (uint8_t)(d >> (8 * k));
  }
  size_t n = 4 * nv;
  int64_t last = 0;
  for (size_t i = 0; i < 3 * ntris; i++) {
    int64_t d = (int64_t)tris[i] - last;
    last = tris[i];
    uint64_t z = d < 0 ? ((uint64_t)(-d) << 1) - 1 : (uint64_t)d << 1;
    do {
      b[n++] = (uint8_t)((z & 0x7f) | (z > 0x7f ? 0x80 : 0));
      z >>= 7;
    } while (z);
  }
  return n;
}

int key_encode(const float *pos, size_t nverts, const uint32_t *tris, size_t ntris, int level, uint8_t **out,
               size_t *len, verr_t *err) {
  *out = NULL;
  *len = 0;
  if (nverts == 0 || nverts > KEY_MAX_VERTS || ntris == 0 || ntris > KEY_MAX_TRIS)
    return verr_set(err, "keyframe encode: %zu vertices, %zu triangles (1..%u, 1..%u)", nverts, ntris, KEY_MAX_VERTS,
                    KEY_MAX_TRIS);
  for (size_t i = 0; i < 3 * ntris; i++)
    if (tris[i] >= nverts)
      return verr_set(err, "keyframe encode: triangle %zu uses vertex %u of %zu", i / 3, tris[i], nverts);
  uint8_t *body = malloc(body_bound(nverts, ntris));
  uLongf cap = compressBound((uLong)body_bound(nverts, ntris));
  uint8_t *blob = malloc(HEADER + cap);
  if (!body || !blob) {
    free(body);
    free(blob);
    return verr_set(err, "keyframe encode: out of memory for %zu vertices", nverts);
  }
  size_t n = make_body(pos, nverts, tris, ntris, body);
  int rc = compress2(blob + HEADER, &cap, body, (uLong)n, level < 1 || level > 9 ? Z_BEST_SPEED : level);
  free(body);
  if (rc != Z_OK) {
    free(blob);
    return verr_set(err, "keyframe encode: deflate failed (zlib %d)", rc);
  }
  memcpy(blob, MAGIC, 4);
  put32(blob + 4, (uint32_t)nverts);
  put32(blob + 8, (uint32_t)ntris);
  put32(blob + 12, (uint32_t)n);
  *out = blob;
  *len = HEADER + cap;
  return 0;
}

/* Parses the inflated body into pos and tris; -1 with err on a defect. */
static int parse_body(const uint8_t *b, size_t n, size_t nverts, size_t ntris, float *pos, uint32_t *tris,
                      verr_t *err) {
  size_t nv = 3 * nverts;
  uint32_t prev[3] = {0, 0, 0};
  for (size_t i = 0; i < nv; i++) {
    uint32_t d = 0;
    for (int k = 0; k < 4; k++) d |= (uint32_t)b[(size_t)k * nv + i] << (8 * k);
    uint32_t u = prev[i % 3] + d;
    prev[i % 3] = u;
    memcpy(&pos[i], &u, 4);
    if (!isfinite(pos[i]))
      return verr_set(err, "keyframe decode: vertex %zu coordinate %zu is not finite", i / 3, i % 3);
  }
  size_t at = 4 * nv;
  int64_t last = 0;
  for (size_t i = 0; i < 3 * ntris; i++) {
    uint64_t z = 0;
    int shift = 0;
    for (;;) {
      if (at >= n) return verr_set(err, "keyframe decode: triangle index %zu of %zu is truncated", i, 3 * ntris);
      uint8_t c = b[at++];
      if (shift > 35) return verr_set(err, "keyframe decode: triangle index %zu is an over-long varint", i);
      z |= (uint64_t)(c & 0x7f) << shift;
      shift += 7;
      if (!(c & 0x80)) break;
    }
    int64_t d = (z & 1) ? -(int64_t)((z + 1) >> 1) : (int64_t)(z >> 1);
    int64_t v = last + d;
    if (v < 0 || v >= (int64_t)nverts)
      return verr_set(err, "keyframe decode: triangle %zu uses vertex %lld of %zu", i / 3, (long long)v, nverts);
    tris[i] = (uint32_t)v;
    last = v;
  }
  if (at != n) return verr_set(err, "keyframe decode: %zu bytes after the last triangle", n - at);
  return 0;
}

int key_decode(const uint8_t *blob, size_t len, float **pos, size_t *nverts, uint32_t **tris, size_t *ntris,
               verr_t *err) {
  *pos = NULL;
  *tris = NULL;
  *nverts = *ntris = 0;
  if (len < HEADER) return verr_set(err, "keyframe decode: %zu bytes, shorter than the %d-byte header", len, HEADER);
  if (memcmp(blob, MAGIC, 4)) return verr_set(err, "keyframe decode: not an encoded keyframe (bad magic)");
  size_t nv = get32(blob + 4), nt = get32(blob + 8), n = get32(blob + 12);
  if (nv == 0 || nv > KEY_MAX_VERTS || nt == 0 || nt > KEY_MAX_TRIS)
    return verr_set(err, "keyframe decode: %zu vertices, %zu triangles (1..%u, 1..%u)", nv, nt, KEY_MAX_VERTS,
                    KEY_MAX_TRIS);
  if (n < 12 * nv + 3 * nt || n > body_bound(nv, nt))
    return verr_set(err, "keyframe decode: body of %zu bytes for %zu vertices and %zu triangles (%zu..%zu)", n, nv, nt,
                    12 * nv + 3 * nt, body_bound(nv, nt));
  uint8_t *body = malloc(n);
  float *p = malloc(3 * nv * sizeof *p);
  uint32_t *t = malloc(3 * nt * sizeof *t);
  if (!body || !p || !t) {
    free(body);
    free(p);
    free(t);
    return verr_set(err, "keyframe decode: out of memory for %zu vertices, %zu triangles", nv, nt);
  }
  uLongf got = (uLongf)n;
  int rc = uncompress(body, &got, blob + HEADER, (uLong)(len - HEADER));
  int bad = 0;
  if (rc != Z_OK || got != n)
    bad = verr_set(err, "keyframe decode: the body does not inflate to its %zu bytes (zlib %d, %lu bytes)", n, rc,
                   (unsigned long)got);
  else
    bad = parse_body(body, n, nv, nt, p, t, err);
  free(body);
  if (bad) {
    free(p);
    free(t);
    return -1;
  }
  *pos = p;
  *tris = t;
  *nverts = nv;
  *ntris = nt;
  return 0;
}

int key_chunk_check(const key_chunk_t *c, uint32_t max_organs, verr_t *err) {
  if (c->organ_id >= max_organs) return verr_set(err, "organ_id %u out of range (0..%u)", c->organ_id, max_organs - 1);
  if (c->count == 0 || c->count > KEY_CHUNKS_MAX || c->index >= c->count)
    return verr_set(err, "chunk %u of %u (1..%u chunks)", c->index, c->count, KEY_CHUNKS_MAX);
  uint64_t first = (uint64_t)c->organ_id * KEY_CHUNKS_MAX + c->index;
  if (c->slot != first && !(2 * c->count <= KEY_CHUNKS_MAX && c->slot == first + c->count))
    return verr_set(err, "slot %u is not organ %u chunk %u (nor its copy)", c->slot, c->organ_id, c->index);
  if (key_chunk_count(c->total_bytes) != c->count)
    return verr_set(err, "%u chunks for %u bytes (%u needed)", c->count, c->total_bytes,
                    key_chunk_count(c->total_bytes));
  uint64_t off = (uint64_t)c->index * KEY_CHUNK_DATA_MAX;
  if (c->offset != off)
    return verr_set(err, "chunk %u at offset %u, not %llu", c->index, c->offset, (unsigned long long)off);
  uint64_t want = c->total_bytes - off < KEY_CHUNK_DATA_MAX ? c->total_bytes - off : KEY_CHUNK_DATA_MAX;
  if (c->len != want)
    return verr_set(err, "chunk %u holds %zu bytes, not %llu", c->index, c->len, (unsigned long long)want);
  return 0;
}

static int same_set(const key_assembly_t *a, const key_chunk_t *c) {
  return a->topology_version == c->topology_version && a->keyframe_seq == c->keyframe_seq && a->count == c->count &&
         a->total_bytes == c->total_bytes && !memcmp(a->digest, c->digest, KEY_DIGEST_LEN);
}

static int start_set(key_assembly_t *a, const key_chunk_t *c, verr_t *err) {
  if (a->cap_buf < c->total_bytes) {
    uint8_t *b = realloc(a->buf, c->total_bytes);
    if (!b) return verr_set(err, "out of memory for a keyframe of %u bytes", c->total_bytes);
    a->buf = b;
    a->cap_buf = c->total_bytes;
  }
  if (a->cap_have < c->count) {
    uint8_t *h = realloc(a->have, c->count);
    if (!h) return verr_set(err, "out of memory for %u chunk flags", c->count);
    a->have = h;
    a->cap_have = c->count;
  }
  memset(a->have, 0, c->count);
  a->active = 1;
  a->topology_version = c->topology_version;
  a->keyframe_seq = c->keyframe_seq;
  a->count = c->count;
  a->total_bytes = c->total_bytes;
  a->received = 0;
  a->sim_time_ns = c->sim_time_ns;
  memcpy(a->digest, c->digest, KEY_DIGEST_LEN);
  return 0;
}

int key_assembly_add(key_assembly_t *a, const key_chunk_t *c, uint32_t max_organs, verr_t *err) {
  if (key_chunk_check(c, max_organs, err)) {
    a->refused++;
    return -1;
  }
  if (a->done && a->done_topology_version == c->topology_version && a->done_keyframe_seq == c->keyframe_seq &&
      !memcmp(a->done_digest, c->digest, KEY_DIGEST_LEN))
    return 0;
  if (!(a->active && same_set(a, c)) && start_set(a, c, err)) {
    a->active = 0;
    a->refused++;
    return -1;
  }
  if (a->have[c->index]) return 0;
  memcpy(a->buf + c->offset, c->data, c->len);
  a->have[c->index] = 1;
  if (++a->received < a->count) return 0;
  a->active = 0;
  uint8_t d[KEY_DIGEST_LEN];
  key_digest(a->buf, a->total_bytes, d);
  if (memcmp(d, a->digest, KEY_DIGEST_LEN)) {
    a->digest_failures++;
    a->refused++;
    return verr_set(err, "topology %u keyframe %u: the %u chunks' digest does not match their content",
                    c->topology_version, c->keyframe_seq, a->count);
  }
  a->done = 1;
  a->done_topology_version = a->topology_version;
  a->done_keyframe_seq = a->keyframe_seq;
  memcpy(a->done_digest, a->digest, KEY_DIGEST_LEN);
  a->completed++;
  return 1;
}

void key_assembly_free(key_assembly_t *a) {
  free(a->buf);
  free(a->have);
  memset(a, 0, sizeof *a);
}

void key_chunk_from_wire(const struct viscera_MeshKeyChunk *s, key_chunk_t *c) {
  *c = (key_chunk_t){.slot = s->slot,
                     .organ_id = s->organ_id,
                     .topology_version = s->topology_version,
                     .keyframe_seq = s->keyframe_seq,
                     .sim_time_ns = s->sim_time_ns,
                     .index = s->index,
                     .count = s->count,
                     .total_bytes = s->total_bytes,
                     .offset = s->offset,
                     .digest = s->digest,
                     .data = s->data._buffer,
                     .len = s->data._length};
}

int key_chunks_write(int32_t w, uint32_t organ_id, uint32_t topology_version, uint32_t keyframe_seq,
                     uint64_t sim_time_ns, const uint8_t *blob, size_t len, uint32_t copies, uint32_t *written,
                     verr_t *err) {
  uint32_t count = key_chunk_count(len);
  if (count == 0 || organ_id >= UINT32_MAX / KEY_CHUNKS_MAX)
    return verr_set(err, "organ %u: an encoded keyframe of %zu bytes does not fit %u chunks", organ_id, len,
                    KEY_CHUNKS_MAX);
  viscera_MeshKeyChunk s;
  memset(&s, 0, sizeof s);
  s.organ_id = organ_id;
  s.topology_version = topology_version;
  s.keyframe_seq = keyframe_seq;
  s.sim_time_ns = sim_time_ns;
  s.count = count;
  s.total_bytes = (uint32_t)len;
  key_digest(blob, len, s.digest);
  /* Two copies when they fit: all of the first, then all of the second, so
   * a burst of losses rarely takes both copies of a chunk. */
  if (copies < 1 || copies > 2 || 2 * count > KEY_CHUNKS_MAX) copies = 1;
  uint32_t slots = copies * count;
  for (uint32_t j = 0; j < slots; j++) {
    uint32_t i = j % count;
    s.slot = organ_id * KEY_CHUNKS_MAX + j;
    s.index = i;
    s.offset = i * KEY_CHUNK_DATA_MAX;
    s.data._buffer = (uint8_t *)blob + s.offset;
    s.data._length = s.data._maximum =
        (uint32_t)(len - s.offset < KEY_CHUNK_DATA_MAX ? len - s.offset : KEY_CHUNK_DATA_MAX);
    dds_return_t rc = dds_write(w, &s);
    if (rc < 0) return verr_set(err, "organ %u: writing keyframe chunk %u failed: %s", organ_id, i, dds_strretcode(rc));
  }
  /* A shorter set leaves the old set's last slots in the history: a late
   * joiner would get them too (they are refused as another set, but cost
   * bytes on the link). */
  for (uint32_t j = slots; j < *written; j++) {
    s.slot = organ_id * KEY_CHUNKS_MAX + j;
    (void)dds_unregister_instance(w, &s);
  }
  *written = slots;
  return (int)slots;
}
