/* SPDX-License-Identifier: Apache-2.0 */
/* fuzz_files: what the file fuzz harnesses share (fuzz_scene.c, fuzz_mesh.c,
 * fuzz_recording.c; issue 15 item 5).
 *
 * Each harness reads its seed corpus (a folder under tests/fuzz/corpus),
 * then for ITERATIONS rounds picks a seed and mutates it with a
 * deterministic generator (splitmix64 from test_rng.h, seeded by SEED and
 * the round), feeds it to the parsers and checks their contracts. A
 * contract broken, a crash or a sanitizer report fails the test; before
 * the round runs, its input is written to CRASH_DIR/<harness>-<seed>-<round>
 * so whatever kills the process can be replayed and then committed to the
 * corpus (the file is removed when the round passes). The time cap is only
 * a safety stop: rounds end early with a note, never a failure.
 *
 * usage: fuzz_X CORPUS_DIR ITERATIONS SEED CRASH_DIR [CAP_SECONDS]
 * Header-only; one harness per process. */
#ifndef VISCERA_FUZZ_FILES_H
#define VISCERA_FUZZ_FILES_H

#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "test_rng.h"

#define FUZZ_MAX_SEEDS 64
#define FUZZ_MAX_INPUT (1 << 18)

typedef struct fuzz_buf {
  unsigned char *p;
  size_t n, cap;
} fuzz_buf_t;

typedef struct fuzz_corpus {
  size_t n;
  char *name[FUZZ_MAX_SEEDS];
  fuzz_buf_t data[FUZZ_MAX_SEEDS];
} fuzz_corpus_t;

typedef struct fuzz_run {
  const char *harness, *corpus_dir, *crash_dir;
  long iterations;
  uint64_t seed;
  double cap_s;
  char pending[1024]; /* the current round's input file */
} fuzz_run_t;

static inline uint64_t fuzz_u64(uint64_t *s) { return (uint64_t)(test_rng_uniform(s) * 18446744073709551616.0); }
static inline size_t fuzz_below(uint64_t *s, size_t n) { return n ? (size_t)(test_rng_uniform(s) * (double)n) : 0; }

static inline int fuzz_buf_reserve(fuzz_buf_t *b, size_t cap) {
  if (cap <= b->cap) return 0;
  unsigned char *p = realloc(b->p, cap);
  if (!p) return -1;
  b->p = p;
  b->cap = cap;
  return 0;
}

static inline int fuzz_read_file(const char *path, fuzz_buf_t *b) {
  FILE *f = fopen(path, "rb");
  if (!f) return -1;
  b->n = 0;
  unsigned char tmp[4096];
  size_t k;
  while ((k = fread(tmp, 1, sizeof tmp, f)) > 0) {
    if (b->n + k > FUZZ_MAX_INPUT || fuzz_buf_reserve(b, b->n + k + 1)) break;
    memcpy(b->p + b->n, tmp, k);
    b->n += k;
  }
  fclose(f);
  if (fuzz_buf_reserve(b, b->n + 1)) return -1;
  b->p[b->n] = 0;
  return 0;
}

static inline int fuzz_write_file(const char *path, const void *p, size_t n) {
  FILE *f = fopen(path, "wb");
  if (!f) return -1;
  int ok = fwrite(p, 1, n, f) == n;
  return fclose(f) == 0 && ok ? 0 : -1;
}

static int fuzz_name_cmp(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

/* The files of dir ending in `ext` (sorted by name, so the run is the same
 * on every file system). */
static inline int fuzz_corpus_load(fuzz_corpus_t *c, const char *dir, const char *ext) {
  memset(c, 0, sizeof *c);
  DIR *d = opendir(dir);
  if (!d) return -1;
  struct dirent *e;
  char *names[FUZZ_MAX_SEEDS];
  size_t n = 0, el = strlen(ext);
  while ((e = readdir(d)) != NULL && n < FUZZ_MAX_SEEDS) {
    size_t l = strlen(e->d_name);
    if (l > el && !strcmp(e->d_name + l - el, ext)) names[n++] = strdup(e->d_name);
  }
  closedir(d);
  qsort(names, n, sizeof *names, fuzz_name_cmp);
  for (size_t i = 0; i < n; i++) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, names[i]);
    c->name[c->n] = names[i];
    if (fuzz_read_file(path, &c->data[c->n]) == 0) c->n++;
  }
  return c->n ? 0 : -1;
}

static inline void fuzz_corpus_free(fuzz_corpus_t *c) {
  for (size_t i = 0; i < c->n; i++) {
    free(c->name[i]);
    free(c->data[i].p);
  }
}

/* Byte-level mutations, 1..4 of them: a flipped bit, a byte set to a
 * boundary or syntax value, a range deleted, a range duplicated, a
 * dictionary token inserted, a run of digits replaced by an extreme
 * number. b keeps a terminating 0. */
static inline void fuzz_mutate(fuzz_buf_t *b, uint64_t *s, const char *const *dict, size_t ndict) {
  static const unsigned char special[] = {0, 0x7f, 0x80, 0xff, '\n', ':', '-', '[', '{', '#', '"', ' ', '.', 'e'};
  static const char *const extreme[] = {
      "1e-300", "1e300",     "-1e308", "0", "-0", "4294967296", "1e-30", "1e30", "9223372036854775807",
      "2e5",    "0.0000001", "-1"};
  int rounds = 1 + (int)fuzz_below(s, 4);
  for (int r = 0; r < rounds; r++) {
    size_t at = fuzz_below(s, b->n + 1);
    switch (fuzz_below(s, 6)) {
    case 0:
      if (b->n) b->p[fuzz_below(s, b->n)] ^= (unsigned char)(1u << fuzz_below(s, 8));
      break;
    case 1:
      if (b->n) b->p[fuzz_below(s, b->n)] = special[fuzz_below(s, sizeof special)];
      break;
    case 2: {
      size_t len = 1 + fuzz_below(s, 16);
      if (at + len > b->n) len = b->n - at;
      memmove(b->p + at, b->p + at + len, b->n - at - len);
      b->n -= len;
      break;
    }
    case 3: {
      if (!b->n) break;
      size_t from = fuzz_below(s, b->n), len = 1 + fuzz_below(s, 64);
      if (from + len > b->n) len = b->n - from;
      if (b->n + len > FUZZ_MAX_INPUT || fuzz_buf_reserve(b, b->n + len + 1)) break;
      unsigned char tmp[64];
      memcpy(tmp, b->p + from, len);
      memmove(b->p + at + len, b->p + at, b->n - at);
      memcpy(b->p + at, tmp, len);
      b->n += len;
      break;
    }
    case 4:
    case 5: {
      const char *tok = NULL;
      size_t start = at, end = at;
      if (fuzz_below(s, 2) && b->n) { /* a number replaced */
        size_t k = fuzz_below(s, b->n);
        while (k < b->n && !(b->p[k] >= '0' && b->p[k] <= '9')) k++;
        if (k < b->n) {
          start = end = k;
          while (end < b->n && strchr("0123456789.eE+-", b->p[end])) end++;
          tok = extreme[fuzz_below(s, sizeof extreme / sizeof *extreme)];
        }
      }
      if (!tok) tok = ndict ? dict[fuzz_below(s, ndict)] : extreme[0];
      size_t tl = strlen(tok), cut = end - start;
      if (b->n - cut + tl > FUZZ_MAX_INPUT || fuzz_buf_reserve(b, b->n - cut + tl + 1)) break;
      memmove(b->p + start + tl, b->p + end, b->n - end);
      memcpy(b->p + start, tok, tl);
      b->n = b->n - cut + tl;
      break;
    }
    }
  }
  b->p[b->n] = 0;
}

static inline double fuzz_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Parses the command line; 0, or -1 after the usage. */
static inline int fuzz_args(fuzz_run_t *r, const char *harness, int argc, char **argv) {
  if (argc < 5) {
    fprintf(stderr, "usage: %s CORPUS_DIR ITERATIONS SEED CRASH_DIR [CAP_SECONDS]\n", harness);
    return -1;
  }
  r->harness = harness;
  r->corpus_dir = argv[1];
  r->iterations = atol(argv[2]);
  r->seed = strtoull(argv[3], NULL, 0);
  r->crash_dir = argv[4];
  r->cap_s = argc > 5 ? atof(argv[5]) : 120;
  return 0;
}

/* The round's input, kept on disk while it runs (`ext`: file ending). */
static inline void fuzz_pending(fuzz_run_t *r, long round, const char *ext, const void *p, size_t n) {
  snprintf(r->pending, sizeof r->pending, "%s/%s-%llu-%ld%s", r->crash_dir, r->harness, (unsigned long long)r->seed,
           round, ext);
  if (fuzz_write_file(r->pending, p, n)) fprintf(stderr, "%s: cannot write %s\n", r->harness, r->pending);
}

/* The round passed: its input is not needed. */
static inline void fuzz_passed(fuzz_run_t *r) {
  if (r->pending[0]) remove(r->pending);
  r->pending[0] = 0;
}

/* A contract broken: says so and keeps the input. */
static inline void fuzz_failed(fuzz_run_t *r, long round, const char *what) {
  fprintf(stderr, "%s: round %ld: %s (input kept: %s; add it to %s)\n", r->harness, round, what, r->pending,
          r->corpus_dir);
  r->pending[0] = 0;
}

#endif
