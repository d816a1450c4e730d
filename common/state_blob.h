/* SPDX-License-Identifier: Apache-2.0 */
/* state_blob: a growable byte buffer written and read in one piece, the
 * format of checkpoints (checkpoint.c) and of the models' topology
 * save/restore hooks (physics/model.h).
 *
 * Writing: sb_put* append (growing by doubling; `bad` set on out of
 * memory, after which every put is ignored). Reading: sb_get* consume from
 * `at` and set `bad` instead of reading past `len`, so a parser reads on
 * and checks `bad` once; values read past the end are 0. Data read from a
 * file is untrusted: sb_count() reads a count and refuses (bad) one whose
 * elements of `elem` bytes cannot all be in the bytes left, so no count
 * from a file ever sizes an allocation larger than the file itself.
 * Native byte order: a checkpoint is read back on the machine that wrote it. */
#ifndef VISCERA_STATE_BLOB_H
#define VISCERA_STATE_BLOB_H

#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct state_blob {
  unsigned char *p;
  size_t len, cap, at;
  int bad;
} state_blob_t;

static inline void sb_put(state_blob_t *b, const void *src, size_t n) {
  if (b->bad || n == 0) return;
  if (b->len + n > b->cap) {
    size_t cap = b->cap ? b->cap : 4096;
    while (cap < b->len + n) cap *= 2;
    unsigned char *p = realloc(b->p, cap);
    if (!p) {
      b->bad = 1;
      return;
    }
    b->p = p;
    b->cap = cap;
  }
  memcpy(b->p + b->len, src, n);
  b->len += n;
}
static inline void sb_put_u64(state_blob_t *b, uint64_t v) { sb_put(b, &v, sizeof v); }
static inline void sb_put_f64(state_blob_t *b, double v) { sb_put(b, &v, sizeof v); }

static inline int sb_get(state_blob_t *b, void *dst, size_t n) {
  if (b->bad || n > b->len - b->at) {
    b->bad = 1;
    memset(dst, 0, n);
    return -1;
  }
  memcpy(dst, b->p + b->at, n);
  b->at += n;
  return 0;
}
static inline uint64_t sb_get_u64(state_blob_t *b) {
  uint64_t v = 0;
  sb_get(b, &v, sizeof v);
  return v;
}
static inline double sb_get_f64(state_blob_t *b) {
  double v = 0;
  sb_get(b, &v, sizeof v);
  return v;
}
/* A count of elements of `elem` bytes that must follow in the blob (0 and
 * bad when they cannot: truncated file or huge count). */
static inline size_t sb_count(state_blob_t *b, size_t elem) {
  uint64_t n = sb_get_u64(b);
  if (b->bad || (elem && n > (b->len - b->at) / elem) || n > SIZE_MAX / 8) {
    b->bad = 1;
    return 0;
  }
  return (size_t)n;
}

#endif
