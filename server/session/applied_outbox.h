/* SPDX-License-Identifier: Apache-2.0 */
/* applied_outbox: the AppliedInput samples (applied_input.h) written to DDS
 * by a thread of their own, off the physics loop.
 *
 * Why: the samples exist for the recording, not for the hand, and their
 * writer keeps a 1000-sample transient-local history (common/dds/vdds.c,
 * QOS_LOG: a late or stalled recorder's second of grace). Cyclone's work on
 * that history made the write cost 2 us at the median but 170 us at the
 * p99 and up to 3 ms, inside the 1 kHz step (docs/numerics.md §11.2). The
 * loop now copies each sample (~0.2 us) into a ring; the thread wakes every
 * APPLIED_OUTBOX_PERIOD_NS (not once per sample: no wake-up per step) and
 * writes what is queued, in order.
 *
 * Nothing is lost while the thread keeps up: the ring holds about a second
 * of one-tool samples (more than 1,200). If it ever fills (the thread starved that
 * long), the sample is dropped and counted as a failed write; its
 * AppliedInput.seq is missing from the recording, as for any lost sample.
 *
 * Threads: applied_outbox_push from one thread (the physics loop) only;
 * start and stop from that thread too. The ring is single-producer,
 * single-consumer (C11 atomics): push never blocks and never allocates. */
#ifndef VISCERA_APPLIED_OUTBOX_H
#define VISCERA_APPLIED_OUTBOX_H

#include <dds/dds.h>
#include <stdint.h>

#include "verr.h"
#include "viscera.h"

#define APPLIED_OUTBOX_BYTES (256u * 1024u)
#define APPLIED_OUTBOX_PERIOD_NS 2000000ull

typedef struct applied_outbox applied_outbox_t;

/* Starts the thread that writes to `writer` (owned by the caller, kept
 * until stop) every period_ns (the server: APPLIED_OUTBOX_PERIOD_NS). NULL
 * with err when it cannot (out of memory, no thread). */
applied_outbox_t *applied_outbox_start(dds_entity_t writer, uint64_t period_ns, verr_t *err);
/* Queues a copy of s (its tools and controls sequences included). 0, or -1
 * when the ring is full (dropped, counted in failed). */
int applied_outbox_push(applied_outbox_t *o, const viscera_AppliedInput *s);
/* Writes everything still queued, stops the thread, frees o; the samples
 * written and the ones dropped or refused by DDS over its life. NULL: no-op. */
void applied_outbox_stop(applied_outbox_t *o, uint64_t *published, uint64_t *failed);

#endif
