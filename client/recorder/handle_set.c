/* SPDX-License-Identifier: Apache-2.0 */
#include "handle_set.h"

#include <stdlib.h>
#include <string.h>

/* Instance handles are sequential-ish counters; mix them so neighbours do
 * not cluster in the table. */
static size_t slot_of(uint64_t h, size_t cap) {
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  return (size_t)h & (cap - 1);
}

bool handle_set_contains(const handle_set_t *s, uint64_t h) {
  if (h == 0 || s->cap == 0) return false;
  for (size_t i = slot_of(h, s->cap);; i = (i + 1) & (s->cap - 1)) {
    if (s->slots[i] == h) return true;
    if (s->slots[i] == 0) return false;
  }
}

static int grow(handle_set_t *s) {
  size_t ncap = s->cap ? s->cap * 2 : 16;
  uint64_t *n = calloc(ncap, sizeof *n);
  if (!n) return -1;
  for (size_t i = 0; i < s->cap; i++) {
    uint64_t h = s->slots[i];
    if (!h) continue;
    size_t j = slot_of(h, ncap);
    while (n[j]) j = (j + 1) & (ncap - 1);
    n[j] = h;
  }
  free(s->slots);
  s->slots = n;
  s->cap = ncap;
  return 0;
}

int handle_set_add(handle_set_t *s, uint64_t h) {
  if (h == 0) return 0;
  if (handle_set_contains(s, h)) return 0;
  /* keep the load factor at most 1/2 so probes stay short */
  if ((s->count + 1) * 2 > s->cap && grow(s) < 0) return -1;
  size_t i = slot_of(h, s->cap);
  while (s->slots[i]) i = (i + 1) & (s->cap - 1);
  s->slots[i] = h;
  s->count++;
  return 0;
}

void handle_set_remove(handle_set_t *s, uint64_t h) {
  if (h == 0 || s->cap == 0) return;
  size_t mask = s->cap - 1, i = slot_of(h, s->cap);
  while (s->slots[i] != h) {
    if (s->slots[i] == 0) return;
    i = (i + 1) & mask;
  }
  /* Backward-shift deletion: move later members of the probe run into the
   * hole so lookups never need tombstones. */
  size_t hole = i;
  for (size_t j = (hole + 1) & mask; s->slots[j]; j = (j + 1) & mask) {
    size_t home = slot_of(s->slots[j], s->cap);
    /* j may move to the hole if its home is not cyclically in (hole, j] */
    bool between = hole <= j ? (home > hole && home <= j) : (home > hole || home <= j);
    if (!between) {
      s->slots[hole] = s->slots[j];
      hole = j;
    }
  }
  s->slots[hole] = 0;
  s->count--;
}

void handle_set_clear(handle_set_t *s) {
  if (s->count) memset(s->slots, 0, s->cap * sizeof *s->slots);
  s->count = 0;
}

void handle_set_free(handle_set_t *s) {
  free(s->slots);
  *s = HANDLE_SET_INIT;
}
