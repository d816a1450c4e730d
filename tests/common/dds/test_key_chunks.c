/* SPDX-License-Identifier: Apache-2.0 */
/* Keyframe chunks (common/dds/key_chunks.c, issue 14): the encoding round
 * trips bit-exactly (the kidney and random meshes); chunks assemble in any
 * order, with repeats (and second copies in their own slots), and a newer set replaces a half-collected one; every
 * damaged or truncated chunk or encoded keyframe is refused with a message
 * naming the defect. Prints the kidney's sizes and encode time (CPU), not
 * asserted. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "check.h"
#include "dds/key_chunks.h"
#include "mesh_import.h"

static uint64_t rng = 0x2545f4914f6cdd1dull;
static uint32_t rnd(void) {
  rng ^= rng << 13;
  rng ^= rng >> 7;
  rng ^= rng << 17;
  return (uint32_t)(rng >> 11);
}

/* err.msg contains want. */
static int says(const verr_t *e, const char *want) {
  if (strstr(e->msg, want)) return 1;
  fprintf(stderr, "  message '%s' lacks '%s'\n", e->msg, want);
  return 0;
}

static void round_trip(const float *pos, size_t nv, const uint32_t *tris, size_t nt, int level) {
  uint8_t *blob;
  size_t len;
  verr_t err;
  CHECK(key_encode(pos, nv, tris, nt, level, &blob, &len, &err) == 0);
  float *p2;
  uint32_t *t2;
  size_t nv2, nt2;
  CHECK(key_decode(blob, len, &p2, &nv2, &t2, &nt2, &err) == 0);
  CHECK(nv2 == nv && nt2 == nt);
  CHECK(!memcmp(p2, pos, 3 * nv * sizeof *pos));
  CHECK(!memcmp(t2, tris, 3 * nt * sizeof *tris));
  free(p2);
  free(t2);
  free(blob);
}

/* The chunks of blob, as a receiver gets them (data borrowed from blob). */
static uint32_t cut(const uint8_t *blob, size_t len, uint32_t organ, uint32_t seq, uint8_t digest[KEY_DIGEST_LEN],
                    key_chunk_t *out) {
  uint32_t n = key_chunk_count(len);
  key_digest(blob, len, digest);
  for (uint32_t i = 0; i < n; i++) {
    size_t off = (size_t)i * KEY_CHUNK_DATA_MAX;
    out[i] = (key_chunk_t){.slot = organ * KEY_CHUNKS_MAX + i,
                           .organ_id = organ,
                           .topology_version = 0,
                           .keyframe_seq = seq,
                           .index = i,
                           .count = n,
                           .total_bytes = (uint32_t)len,
                           .offset = (uint32_t)off,
                           .digest = digest,
                           .data = blob + off,
                           .len = len - off < KEY_CHUNK_DATA_MAX ? len - off : KEY_CHUNK_DATA_MAX};
  }
  return n;
}

/* One field of a sound chunk damaged at a time; each refused, naming it. */
static void chunk_refusals(const key_chunk_t *good) {
  static const char *const want[] = {"organ_id",     "chunk 0 of 0", "chunk 5 of 5", "chunk 0 of 5000",
                                     "is not organ", "chunks for",   "offset",       "holds"};
  for (int i = 0; i < 8; i++) {
    key_chunk_t c = *good;
    switch (i) {
    case 0:
      c.organ_id = 16, c.slot = 16 * KEY_CHUNKS_MAX + c.index;
      break;
    case 1:
      c.count = 0, c.index = 0;
      break;
    case 2:
      c.count = 5, c.index = 5;
      break;
    case 3:
      c.count = 5000, c.index = 0;
      break;
    case 4:
      c.slot = c.slot + 1;
      break;
    case 5:
      c.total_bytes = 100;
      break;
    case 6:
      c.offset = c.offset + 7;
      break;
    default:
      c.len = 10;
      break;
    }
    verr_t err;
    int rc = key_chunk_check(&c, 16, &err);
    CHECK(rc == -1);
    if (rc == -1) CHECK(says(&err, want[i]));
  }
}

int main(void) {
  /* The kidney, as the server publishes it. */
  const char *src = getenv("VISCERA_SOURCE_DIR");
  char path[1024];
  snprintf(path, sizeof path, "%s/assets/meshes/kidney.obj", src ? src : ".");
  mesh_t m;
  verr_t err;
  CHECK(mesh_import(path, &m, &err) == 0);
  float *pos = malloc(3 * m.nverts * sizeof *pos);
  for (size_t i = 0; i < 3 * m.nverts; i++) pos[i] = (float)m.pos[i];
  for (int level = 1; level <= 9; level += 8) round_trip(pos, m.nverts, m.tris, m.ntris, level);
  uint8_t *blob;
  size_t len;
  clock_t c0 = clock();
  CHECK(key_encode(pos, m.nverts, m.tris, m.ntris, 1, &blob, &len, &err) == 0);
  double enc_ms = (double)(clock() - c0) * 1e3 / CLOCKS_PER_SEC;
  printf("kidney: %zu vertices, %zu triangles: MeshState %zu bytes, encoded %zu bytes in %u chunks (level 1, %.2f ms "
         "CPU)\n",
         m.nverts, m.ntris, 12 * m.nverts + 12 * m.ntris, len, key_chunk_count(len), enc_ms);
  CHECK(len < (12 * m.nverts + 12 * m.ntris) / 3);

  /* Random meshes: any floats (signs, tiny, huge), any index order. */
  for (int trial = 0; trial < 50; trial++) {
    size_t nv = 1 + rnd() % 300, nt = 1 + rnd() % 600;
    float *p = malloc(3 * nv * sizeof *p);
    uint32_t *t = malloc(3 * nt * sizeof *t);
    for (size_t i = 0; i < 3 * nv; i++) p[i] = ((float)rnd() / 2097152.0f - 1.0f) * (trial % 2 ? 1e-30f : 1e20f);
    for (size_t i = 0; i < 3 * nt; i++) t[i] = rnd() % (uint32_t)nv;
    round_trip(p, nv, t, nt, 1 + trial % 9);
    free(p);
    free(t);
  }

  /* Chunks: reverse order with repeats; then a newer set half way. */
  static key_chunk_t ch[KEY_CHUNKS_MAX], ch2[KEY_CHUNKS_MAX];
  uint8_t dig[KEY_DIGEST_LEN], dig2[KEY_DIGEST_LEN];
  uint32_t n = cut(blob, len, 3, 1, dig, ch);
  CHECK(n >= 2);
  key_assembly_t a = {0};
  int done = 0;
  for (uint32_t k = n; k-- > 0;) {
    CHECK(key_assembly_add(&a, &ch[k], 16, &err) >= 0);
    key_chunk_t copy = ch[k]; /* the second copy of the same chunk (key_chunks.h KEY_CHUNK_COPIES) */
    copy.slot += n;
    int r = key_assembly_add(&a, &copy, 16, &err); /* a repeat */
    if (r == 1) done++;
  }
  /* The last add of the reverse loop completes the set (its repeat is ignored). */
  CHECK(a.completed == 1 && a.total_bytes == len && !memcmp(a.buf, blob, len));
  CHECK(key_assembly_add(&a, &ch[0], 16, &err) == 0); /* the completed set again: nothing */
  CHECK(a.completed == 1 && done == 0);
  uint8_t *blob2 = malloc(len);
  memcpy(blob2, blob, len);
  uint32_t n2 = cut(blob2, len, 3, 2, dig2, ch2);
  CHECK(key_assembly_add(&a, &ch[0], 16, &err) == 0);
  for (uint32_t k = 0; k < n2; k++) {
    int r = key_assembly_add(&a, &ch2[k], 16, &err);
    CHECK(r == (k + 1 == n2 ? 1 : 0));
  }
  CHECK(a.completed == 2 && a.keyframe_seq == 2);

  /* Damaged chunks: each field, one at a time. */
  chunk_refusals(&ch[1]);
  /* A flipped data byte: the whole set fails its digest. */
  key_assembly_free(&a);
  memset(&a, 0, sizeof a);
  blob2[len / 2] ^= 0x40;
  for (uint32_t k = 0; k < n; k++) {
    key_chunk_t c = ch[k];
    c.data = blob2 + c.offset;
    int r = key_assembly_add(&a, &c, 16, &err);
    CHECK(r == (k + 1 == n ? -1 : 0));
    if (r < 0) CHECK(says(&err, "digest does not match"));
  }
  CHECK(a.digest_failures == 1 && a.completed == 0);
  key_assembly_free(&a);

  /* Damaged encoded keyframes. */
  float *p2;
  uint32_t *t2;
  size_t nv2, nt2;
  CHECK(key_decode(blob, 10, &p2, &nv2, &t2, &nt2, &err) == -1 && says(&err, "shorter than"));
  memcpy(blob2, blob, len);
  blob2[0] = 'X';
  CHECK(key_decode(blob2, len, &p2, &nv2, &t2, &nt2, &err) == -1 && says(&err, "bad magic"));
  CHECK(key_decode(blob, len - 9, &p2, &nv2, &t2, &nt2, &err) == -1 && says(&err, "does not inflate"));
  memcpy(blob2, blob, len);
  blob2[len - 20] ^= 0x11;
  CHECK(key_decode(blob2, len, &p2, &nv2, &t2, &nt2, &err) == -1 && says(&err, "does not inflate"));
  memcpy(blob2, blob, len);
  blob2[4] = blob2[5] = blob2[6] = blob2[7] = 0xff; /* 4 billion vertices */
  CHECK(key_decode(blob2, len, &p2, &nv2, &t2, &nt2, &err) == -1 && says(&err, "vertices"));
  memcpy(blob2, blob, len);
  blob2[8] = (uint8_t)(blob2[8] - 1); /* one triangle fewer than the body holds */
  CHECK(key_decode(blob2, len, &p2, &nv2, &t2, &nt2, &err) == -1 && says(&err, "bytes after the last triangle"));
  /* A triangle index out of range: two vertices, a triangle using a third. */
  const float tp[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const uint32_t tt[3] = {0, 1, 2};
  uint8_t *b3;
  size_t l3;
  CHECK(key_encode(tp, 3, tt, 1, 6, &b3, &l3, &err) == 0);
  free(b3);
  CHECK(key_encode(tp, 2, tt, 1, 6, &b3, &l3, &err) == -1 && says(&err, "uses vertex 2") && !b3);
  /* Non-finite positions are refused on decode. */
  float nanp[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  nanp[4] = 1.0f / 0.0f;
  CHECK(key_encode(nanp, 3, tt, 1, 6, &b3, &l3, &err) == 0);
  CHECK(key_decode(b3, l3, &p2, &nv2, &t2, &nt2, &err) == -1 && says(&err, "not finite"));
  free(b3);
  CHECK(key_chunk_count(0) == 0 && key_chunk_count(KEY_BLOB_MAX + 1) == 0 && key_chunk_count(KEY_CHUNK_DATA_MAX) == 1 &&
        key_chunk_count(KEY_CHUNK_DATA_MAX + 1) == 2);

  /* Mutated encodings and chunks: refused or decoded, never a crash or a
   * read out of bounds (the sanitizer pass runs this too). */
  for (int trial = 0; trial < 300; trial++) {
    memcpy(blob2, blob, len);
    for (int k = 0, nk = 1 + (int)(rnd() % 8); k < nk; k++) blob2[rnd() % len] ^= (uint8_t)(1u << (rnd() % 8));
    size_t cutlen = trial % 3 ? len : 1 + rnd() % len;
    if (key_decode(blob2, cutlen, &p2, &nv2, &t2, &nt2, &err) == 0) {
      CHECK(nv2 >= 1 && nv2 <= KEY_MAX_VERTS && nt2 >= 1 && nt2 <= KEY_MAX_TRIS);
      for (size_t i = 0; i < 3 * nt2; i++) CHECK(t2[i] < nv2);
      free(p2);
      free(t2);
    }
    key_chunk_t c = ch[rnd() % n];
    uint32_t *fields[] = {&c.slot, &c.organ_id, &c.index, &c.count, &c.total_bytes, &c.offset};
    *fields[rnd() % 6] = rnd() % 3 ? rnd() % 4096 : rnd();
    if (rnd() % 4 == 0) c.len = rnd() % (2 * KEY_CHUNK_DATA_MAX);
    if (c.len > KEY_CHUNK_DATA_MAX) c.len = KEY_CHUNK_DATA_MAX; /* the data buffer behind it is this long at most */
    if (c.offset + (size_t)c.len > len) c.data = blob;          /* keep the borrowed bytes inside the buffer */
    key_assembly_add(&a, &c, 16, &err);
  }
  key_assembly_free(&a);

  free(blob2);
  free(blob);
  free(pos);
  mesh_free(&m);
  return check_report("test_key_chunks");
}
