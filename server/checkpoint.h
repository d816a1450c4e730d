/* checkpoint: the scene's state on disk, so a server killed mid-session
 * (crash, kill -9, power) restarts where it was instead of from rest
 * (issue 7, fault tolerance).
 *
 * What is saved (format 2): simulated time and step count; every organ's
 * node positions and velocities and, for an organ whose topology changed
 * (a cut, an adaptive refinement; topology_version > 0), what its model
 * needs to rebuild that topology (model.h save/restore_topology: pbd,
 * xpbd and mass_spring_surface after cuts, adaptive_mass_spring after
 * refinement; a model without those hooks could not be checkpointed once
 * its topology changed, and the file would keep the last state that could
 * be saved); the stones (position, held or not, removed);
 * the tasks (started, completed, start and end times); each tool's
 * palpation measures (thresholds.h) and tally (tool_metrics.h: grasps,
 * time holding); each tool's role (tool_roles.h: owner, guide, authority,
 * coupling), so an instructor's assignment or take-over outlives a crash.
 * What is not: tool contact and grasps (tools re-enter from outside after a
 * restart: a restarted server never pushes a hand that is already inside,
 * a held stone is dropped where it was, held tissue let go), a cut in
 * progress (ended by the restart), the internal caches of a model (rebuilt
 * from positions by its next step; the render surface of an uncut
 * volumetric model follows at that step).
 *
 * The file is untrusted on load: magic and format version (a file of
 * another format is refused, naming both), scene name, organ, tool, task
 * and object counts and the node counts of unchanged organs must match the
 * running scene, every count is bounded by the bytes present, a CRC-32
 * covers everything, values must be finite and in range; anything else is
 * refused with a message naming the file and what is wrong, and the server
 * starts from rest. Writing is atomic (temporary file, fsync, rename), so a
 * kill during a write leaves the previous checkpoint intact.
 * Allocation: one buffer per save/load, outside the physics step. */
#ifndef VISCERA_CHECKPOINT_H
#define VISCERA_CHECKPOINT_H

#include "scene_runtime.h"
#include "training/thresholds.h"
#include "tool_roles.h"
#include "tool_metrics.h"
#include "verr.h"

#include <stdint.h>

/* Writes the state of `rt`, the per-tool trackers `thr` and tallies
 * `tally` (rt->ntools each) and the tools' roles (`roles`, NULL: none
 * saved; on load NULL ignores the file's) to `path`. -1 with err when it cannot (a model
 * that cannot save its changed topology, out of memory, write error). */
int checkpoint_save(const char *path, const runtime_t *rt, const thr_tracker_t *thr, const tool_tally_t *tally,
                    const tool_roles_t *roles, verr_t *err);

/* Restores a checkpoint written for the same scene into `rt`, `thr` and
 * `tally`. Returns 1 when restored (organs with a restored topology already
 * followed: runtime_topology_restored), 0 when `path` does not exist (fresh
 * start), -1 with err when the file is unreadable, damaged, of another
 * format or for another scene (rt, thr and tally are then as from rest:
 * unchanged, or rebuilt from the scene when a topology restore failed
 * midway), -2 when that rebuild failed too (out of memory: rt is unusable). */
int checkpoint_load(const char *path, runtime_t *rt, thr_tracker_t *thr, tool_tally_t *tally, tool_roles_t *roles,
                    verr_t *err);

/* Periodic checkpoints from the physics loop without waiting on the disk:
 * submit() copies the state (no allocation once the buffers have grown;
 * a cut organ's topology is serialised too) and a writer thread writes it atomically; a state that cannot be saved
 * is skipped, said once on stderr. stop() writes what is pending,
 * joins the thread and frees it; -1 with err if any write failed. */
typedef struct checkpointer checkpointer_t;
checkpointer_t *checkpointer_start(const char *path, verr_t *err);
void checkpointer_submit(checkpointer_t *c, const runtime_t *rt, const thr_tracker_t *thr, const tool_tally_t *tally,
                         const tool_roles_t *roles);
int checkpointer_stop(checkpointer_t *c, uint64_t *written, verr_t *err);

#endif
