/* SPDX-License-Identifier: Apache-2.0 */
/* checkpoint_state: the scene's state as bytes and back, without files or
 * networking (the session's checkpoint, session/checkpoint.h, puts these
 * bytes in a file with a magic, a format version and a CRC).
 *
 * What the core saves: simulated time and step count; every organ's node
 * positions and velocities and, for an organ whose topology changed (a cut,
 * an adaptive refinement; topology_version > 0), what its model needs to
 * rebuild that topology (model.h save/restore_topology, or, for a
 * tetrahedral organ cut by a scalpel, its cutter: step_cut.h
 * scalpel_save_topology); the tasks
 * (started, completed, start and end times); the stones (position, held or
 * not, removed). The session adds its own records where the format gives
 * them a place: one per tool after the organs, and a tail after the stones
 * (ckpt_session_io_t).
 * What is not saved: tool contact and grasps (tools re-enter from outside
 * after a restart, a held stone is dropped where it was, held tissue let
 * go), a cut in progress, the internal caches of a model (rebuilt from
 * positions by its next step).
 *
 * The bytes are untrusted on restore: scene name, organ, tool, task and
 * object counts and the node counts of unchanged organs must match the
 * running scene, every count is bounded by the bytes present, values must
 * be finite and in range; anything else is refused, naming what is wrong,
 * before the runtime is changed. */
#ifndef VISCERA_CHECKPOINT_STATE_H
#define VISCERA_CHECKPOINT_STATE_H

#include <stddef.h>

#include "runtime/scene_runtime.h"
#include "state_blob.h"
#include "verr.h"

/* The session's records in the state (all hooks may be NULL: none). */
typedef struct ckpt_session_io {
  void *ctx;
  /* Appends tool t's record (after the organs, for t < rt->ntools). */
  void (*put_tool)(void *ctx, state_blob_t *b, size_t t);
  /* Appends the records after the stones. */
  void (*put_tail)(void *ctx, state_blob_t *b);
  /* Read and check what put_tool / put_tail wrote, keeping it aside;
   * NULL when it is good, else what is wrong (the state is refused). */
  const char *(*get_tool)(void *ctx, state_blob_t *b, size_t t);
  const char *(*get_tail)(void *ctx, state_blob_t *b);
  /* After the runtime took the restored state: adopt what was kept aside. */
  void (*apply)(void *ctx);
} ckpt_session_io_t;

/* Appends the state of `rt` (and the session's records) to b. 0, or -1 with
 * err: a model that cannot save its changed topology, out of memory. */
int ckpt_state_put(state_blob_t *b, const runtime_t *rt, const ckpt_session_io_t *io, verr_t *err);

/* Restores the state in b (from b->at to b->len, exactly) into `rt`.
 * Returns 1 when restored (organs with a restored topology already
 * followed: runtime_topology_restored); -1 when refused, with what is
 * wrong in `what` (rt untouched); -3 when a model's topology restore failed
 * (err says why; rt was rebuilt from its scene, as from rest); -2 when that
 * rebuild failed too (out of memory: rt is unusable). */
int ckpt_state_get(state_blob_t *b, runtime_t *rt, const ckpt_session_io_t *io, char *what, size_t whatlen,
                   verr_t *err);

/* The simulated time (s) a state starts at, read from its header without
 * restoring it (viscera-resim bounds a resumed recording's sim times by
 * it). 0 with *sim_time set; -1 when the bytes are shorter than the header
 * or the time is not finite and >= 0. The bytes are untrusted. */
int ckpt_state_sim_time(const void *p, size_t len, double *sim_time);

#endif
