/* checkpoint: the scene's state on disk, so a server killed mid-session
 * (crash, kill -9, power) restarts where it was instead of from rest
 * (issue 7, fault tolerance).
 *
 * What is saved: simulated time and step count, every organ's node
 * positions and velocities, and each tool's palpation measures. What is not:
 * tool contact (tools re-enter from outside after a restart: a restarted
 * server never pushes a hand that is already inside) and the internal
 * caches of a model (rebuilt from positions by its next step; the render
 * surface of a volumetric model follows at that step).
 *
 * The file is untrusted on load: magic, version, scene name, organ count,
 * node counts and topology versions must match the running scene, sizes are
 * bounded, a CRC-32 covers everything, and values must be finite; anything
 * else is refused with a message naming the file and what is wrong, and the
 * server starts from rest. Writing is atomic (temporary file, fsync,
 * rename), so a kill during a write leaves the previous checkpoint intact.
 * Allocation: one buffer per save/load, outside the physics step. */
#ifndef VISCERA_CHECKPOINT_H
#define VISCERA_CHECKPOINT_H

#include "scene_runtime.h"
#include "thresholds.h"
#include "verr.h"

#include <stdint.h>

/* Writes the state of `rt` and the per-tool trackers `thr` to `path`. */
int checkpoint_save(const char *path, const runtime_t *rt, const thr_tracker_t *thr, verr_t *err);

/* Restores a checkpoint written for the same scene into `rt` and `thr`.
 * Returns 1 when restored, 0 when `path` does not exist (fresh start), -1
 * with err when the file is unreadable, damaged or for another scene (rt
 * and thr are then unchanged). */
int checkpoint_load(const char *path, runtime_t *rt, thr_tracker_t *thr, verr_t *err);

/* Periodic checkpoints from the physics loop without waiting on the disk:
 * submit() copies the state (no allocation once the buffers have grown)
 * and a writer thread writes it atomically. stop() writes what is pending,
 * joins the thread and frees it; -1 with err if any write failed. */
typedef struct checkpointer checkpointer_t;
checkpointer_t *checkpointer_start(const char *path, verr_t *err);
void checkpointer_submit(checkpointer_t *c, const runtime_t *rt, const thr_tracker_t *thr);
int checkpointer_stop(checkpointer_t *c, uint64_t *written, verr_t *err);

#endif
