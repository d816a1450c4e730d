/* SPDX-License-Identifier: Apache-2.0 */
/* applied_input: what the server applied to its runtime in one loop
 * iteration, published as one AppliedInput sample (idl/viscera.idl, issue
 * 16), so a recording holds exactly the inputs viscera-resim must replay:
 * every effective tool command handed to the core (the owner's, the
 * guide's or their mix: tool_roles.h), every release, every SessionControl
 * with its outcome, in the order the server applied them.
 *
 * The header of a sample (step, simulated time, epoch, paused) is the
 * state when its first entry was added; a full buffer is published and a
 * new sample started with the state then (a rebuild in between moves the
 * step back to 0 and the epoch on). Plain buffers, no allocation; the
 * server thread only. With an outbox (applied_outbox.h) a closed sample is
 * queued for its writer thread instead of written here. */
#ifndef VISCERA_APPLIED_INPUT_H
#define VISCERA_APPLIED_INPUT_H

#include <dds/dds.h>
#include <stddef.h>
#include <stdint.h>

#include "runtime/scene_runtime.h"
#include "session/applied_outbox.h"
#include "viscera.h"

#define APPLIED_MAX_TOOLS (2 * SCENE_MAX_TOOLS)
#define APPLIED_MAX_CONTROLS 16

typedef struct applied_input {
  dds_entity_t writer;      /* 0: collect only (tests) */
  applied_outbox_t *outbox; /* NULL: written here; else queued (its counts join published/failed at its stop) */
  const runtime_t *rt;      /* the server's runtime (its address survives a rebuild) */
  const int *paused;        /* the session's pause flag */
  uint64_t tick;            /* the current loop iteration, from 1 */
  uint32_t epoch;           /* rebuilds so far */
  int open;                 /* a sample is being filled */
  viscera_AppliedInput cur; /* header of the open sample */
  viscera_AppliedTool tools[APPLIED_MAX_TOOLS];
  viscera_AppliedControl controls[APPLIED_MAX_CONTROLS];
  uint64_t seq;               /* samples closed (the last one's AppliedInput.seq) */
  uint64_t published, failed; /* samples written, writes that failed */
} applied_input_t;

void applied_input_init(applied_input_t *ai, dds_entity_t writer, const runtime_t *rt, const int *paused);
/* A new loop iteration: publishes what the last one collected. */
void applied_input_tick(applied_input_t *ai);
/* Tool t took command `in` (runtime_command_tool). */
void applied_input_command(applied_input_t *ai, size_t t, const tool_input_t *in);
/* Tool t was released (runtime_release_tool). */
void applied_input_release(applied_input_t *ai, size_t t);
/* Before acting on a SessionControl: opens a sample with room for it, so
 * its header is the state before a rebuild the control may cause. */
void applied_input_begin_control(applied_input_t *ai);
/* The SessionControl was acted on (after applied_input_begin_control): result 0 applied, 1 applied with a
 * rebuild, 2 rebuild refused by the models (old scene restarted), -1
 * refused; task = the task index START_TASK started, else -1. */
void applied_input_control(applied_input_t *ai, const viscera_SessionControl *c, int result, int task);
/* The runtime was rebuilt (RESET, SET_MATERIAL): the epoch moves on. */
void applied_input_rebuilt(applied_input_t *ai);
/* Publishes the open sample, if any. */
void applied_input_flush(applied_input_t *ai);

#endif
