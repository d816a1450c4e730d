/* SPDX-License-Identifier: Apache-2.0 */
/* key_chunks: a keyframe (one organ's float positions and triangles, as in
 * MeshState) in a compact, lossless encoding, cut into chunks that each fit
 * one datagram of deploy/cyclonedds-site.xml (issue 14: keyframes that
 * survive a lossy link). The MeshKeyChunk topic carries the chunks.
 *
 * Why chunks: Cyclone repairs a lost fragment of a large sample only after
 * the reader has seen the sample's first fragment and asked again, about a
 * round trip per refetch; a set of small samples is repaired in one
 * NACK per round trip, all missing chunks at once, each independently.
 * Why the encoding: fewer chunks to lose and fewer bytes per viewer.
 *
 * Encoded keyframe (key_encode): "VKC1", then little-endian u32 vertex
 * count, triangle count and body length, then the body deflated (zlib).
 * Body: the positions' IEEE-754 bit patterns, each coordinate minus the
 * same coordinate of the previous vertex (mod 2^32), stored byte plane by
 * byte plane (all low bytes first); then every triangle index minus the
 * previous index, zig-zag varint. Lossless: decoding gives the exact
 * floats, so a late joiner ends on the server's mesh within q/2 as with
 * MeshState.
 *
 * Every chunk and every encoded keyframe is untrusted input: counts,
 * offsets, sizes, the digest of the whole (SHA-256), the body length, every
 * index and every coordinate are checked; a refusal says what and where.
 * Memory is bounded: one assembly per organ of at most KEY_BLOB_MAX bytes.
 * No global state; not thread-safe per assembly. */
#ifndef VISCERA_KEY_CHUNKS_H
#define VISCERA_KEY_CHUNKS_H

#include <stddef.h>
#include <stdint.h>

#include "verr.h"

/* Data bytes per chunk: a MeshKeyChunk sample (about 100 bytes of header
 * and key) plus its RTPS submessage stays below the 1,280-byte FragmentSize
 * and the 1,400-byte MaxMessageSize of deploy/cyclonedds-site.xml, so it is
 * never fragmented (with DDS Security's few dozen bytes of overhead too). */
#define KEY_CHUNK_DATA_MAX 1100u
/* Chunks per organ (viscera.idl KEY_CHUNKS_PER_ORGAN): the slot key is
 * organ_id * KEY_CHUNKS_MAX + index. A keyframe that does not fit is
 * published as MeshState only. */
#define KEY_CHUNKS_MAX 1024u
/* Copies of each chunk the server writes (2 only when 2 * count <=
 * KEY_CHUNKS_MAX): copy 1 of chunk i is in slot organ_id * KEY_CHUNKS_MAX +
 * count + i, and receivers accept either. One by default: at 100 ms one way
 * a second copy did not shorten the wait measurably (3 interleaved runs each
 * at 5 and 10 % loss: median 470 ms with one, 484 ms with two, load 15-21),
 * because the wait is mostly the handshake before a late joiner gets the
 * history (0 % loss: 370-460 ms), not the repair of lost chunks.
 * VISCERA_KEY_CHUNK_COPIES=2 in the server's environment writes two. */
#define KEY_CHUNK_COPIES 1u
#define KEY_BLOB_MAX (KEY_CHUNK_DATA_MAX * KEY_CHUNKS_MAX)
/* Largest keyframe decoded (as organ_state.h accepts). */
#define KEY_MAX_VERTS (1u << 22)
#define KEY_MAX_TRIS (1u << 23)
#define KEY_DIGEST_LEN 32

/* Encodes nverts vertices (3 floats each) and ntris triangles (3 indices
 * each, < nverts). *out is malloc'd (the caller frees), *len its size.
 * level: zlib level 1..9. Returns 0, or -1 with err. */
int key_encode(const float *pos, size_t nverts, const uint32_t *tris, size_t ntris, int level, uint8_t **out,
               size_t *len, verr_t *err);

/* Decodes an encoded keyframe of len bytes. *pos (3 *nverts floats) and
 * *tris (3 *ntris indices) are malloc'd (the caller frees both). Refuses
 * (-1, err naming the defect, nothing allocated) a bad magic, counts out of
 * range, a body that does not inflate to exactly its stated length, a
 * truncated varint, an index out of range, trailing bytes, a non-finite
 * coordinate. */
int key_decode(const uint8_t *blob, size_t len, float **pos, size_t *nverts, uint32_t **tris, size_t *ntris,
               verr_t *err);

/* The SHA-256 of a buffer, raw (32 bytes). */
void key_digest(const uint8_t *data, size_t len, uint8_t out[KEY_DIGEST_LEN]);

/* Chunks needed for an encoded keyframe of len bytes (0 when len is 0 or
 * above KEY_BLOB_MAX). Chunk i holds bytes [i * KEY_CHUNK_DATA_MAX, ...). */
uint32_t key_chunk_count(size_t len);

/* One received chunk, as the wire has it (borrowed data). */
typedef struct key_chunk {
  uint32_t slot, organ_id, topology_version, keyframe_seq;
  uint64_t sim_time_ns;
  uint32_t index, count, total_bytes, offset;
  const uint8_t *digest; /* KEY_DIGEST_LEN bytes */
  const uint8_t *data;
  size_t len;
} key_chunk_t;

/* Checks a chunk on its own: slot = organ_id * KEY_CHUNKS_MAX + index
 * (or + count + index, its copy, when 2 count <= KEY_CHUNKS_MAX),
 * organ_id < max_organs, count 1..KEY_CHUNKS_MAX and the chunks needed for
 * total_bytes, index < count, offset = index * KEY_CHUNK_DATA_MAX, len =
 * the bytes of total_bytes from offset (at most KEY_CHUNK_DATA_MAX).
 * Returns 0, or -1 with err. */
int key_chunk_check(const key_chunk_t *c, uint32_t max_organs, verr_t *err);

/* Assembly of one organ's current chunk set. */
typedef struct key_assembly {
  int active; /* a set is being collected */
  uint32_t topology_version, keyframe_seq, count, total_bytes, received;
  uint64_t sim_time_ns;
  uint8_t digest[KEY_DIGEST_LEN];
  uint8_t *buf;  /* total_bytes */
  uint8_t *have; /* count flags */
  size_t cap_buf, cap_have;
  /* The last completed set: its repeats are ignored. */
  int done;
  uint32_t done_topology_version, done_keyframe_seq;
  uint8_t done_digest[KEY_DIGEST_LEN];
  uint64_t refused, completed, digest_failures;
} key_assembly_t;

/* Adds a chunk that passed key_chunk_check (checked again here). A chunk
 * of another set (numbers, digest, count or size) abandons the set being
 * collected and starts its own (the newest set wins, as MeshState does; a
 * restarted server starts again at 0). A repeat of a chunk already held,
 * or of the last completed set, changes nothing. Returns 1 when the set is
 * complete and its digest matches (the encoded keyframe is then
 * a->buf[0 .. a->total_bytes), until the next call), 0 when kept or
 * ignored, -1 when refused (err; the chunk is dropped; a digest mismatch
 * drops the whole set). */
int key_assembly_add(key_assembly_t *a, const key_chunk_t *c, uint32_t max_organs, verr_t *err);
void key_assembly_free(key_assembly_t *a);

/* The wire side (MeshKeyChunk, viscera.idl). */
struct viscera_MeshKeyChunk;
/* A received sample as a key_chunk_t (borrows its data). */
void key_chunk_from_wire(const struct viscera_MeshKeyChunk *s, key_chunk_t *c);
/* Writes an encoded keyframe as its chunks (copies: 1, or 2 when they fit;
 * KEY_CHUNK_COPIES is the product's choice) with writer w, then unregisters the slots [slots, *written) a
 * previous, longer set of this organ left in the writer's transient-local
 * history, so a late joiner gets one set. *written becomes the number of
 * samples (slots) written. Returns that number, or -1 with err (a set too
 * large for KEY_CHUNKS_MAX is not written: -1 too). */
int key_chunks_write(int32_t w, uint32_t organ_id, uint32_t topology_version, uint32_t keyframe_seq,
                     uint64_t sim_time_ns, const uint8_t *blob, size_t len, uint32_t copies, uint32_t *written,
                     verr_t *err);

#endif
