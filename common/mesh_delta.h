/* SPDX-License-Identifier: Apache-2.0 */
/* mesh_delta: quantized, cumulative vertex deltas against a keyframe.
 *
 * Contract: for any keyframe K (float positions as published) and current
 * positions X, encode() lists every vertex whose rounded displacement
 * round((X - K) / q) is non-zero; apply() on K reproduces X within q / 2 per
 * coordinate (plus float rounding). Deltas are cumulative, so the newest delta
 * alone plus its keyframe gives the current mesh and a lost delta costs nothing. */
#ifndef VISCERA_MESH_DELTA_H
#define VISCERA_MESH_DELTA_H

#include <stddef.h>
#include <stdint.h>

#include "verr.h"

#define MESH_DELTA_QMAX 32767

/* Encodes into idx[] / dq[] (capacity nverts and 3 * nverts). Returns the
 * number of changed vertices, or -1 when a displacement exceeds the int16
 * range (the caller must publish a new keyframe) or q is not positive. */
long mesh_delta_encode(const float *key, const double *cur, size_t nverts, float q, uint32_t *idx, int16_t *dq);

/* Writes key + delta into out[3 * nverts]. Untrusted input: rejects indices
 * out of range or not strictly ascending, a non-finite or non-positive q,
 * and dq of the wrong length, naming what is wrong; out is then unspecified. */
int mesh_delta_apply(const float *key, size_t nverts, float q, const uint32_t *idx, size_t count, const int16_t *dq,
                     size_t dq_len, float *out, verr_t *err);

#endif
