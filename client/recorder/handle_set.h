/* SPDX-License-Identifier: Apache-2.0 */
/* handle_set: a set of 64-bit DDS instance handles (open addressing).
 *
 * The capture uses it to remember, within one drain of a reader, which
 * instances it has already recorded as disposed or unregistered, so a
 * dispose that Cyclone only reports through the instance state of data
 * samples is stored once even when those samples span several takes. Handles are never 0 in Cyclone; 0 is the
 * empty-slot marker and cannot be stored. Memory is proportional to the number of members. */
#ifndef VISCERA_REC_HANDLE_SET_H
#define VISCERA_REC_HANDLE_SET_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct handle_set {
  uint64_t *slots;
  size_t cap; /* power of two or 0 */
  size_t count;
} handle_set_t;

#define HANDLE_SET_INIT ((handle_set_t){NULL, 0, 0})

bool handle_set_contains(const handle_set_t *s, uint64_t h);
/* Returns -1 on allocation failure (the set is unchanged), 0 otherwise. */
int handle_set_add(handle_set_t *s, uint64_t h);
void handle_set_remove(handle_set_t *s, uint64_t h);
/* Empties the set, keeping its memory. */
void handle_set_clear(handle_set_t *s);
void handle_set_free(handle_set_t *s);

#endif
