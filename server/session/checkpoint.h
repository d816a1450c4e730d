/* SPDX-License-Identifier: Apache-2.0 */
/* checkpoint: the scene's state on disk, so a server killed mid-session
 * (crash, kill -9, power) restarts where it was instead of from rest
 * (issue 7, fault tolerance).
 *
 * What is saved (format 2): the core's state (runtime/checkpoint_state.h:
 * simulated time and step count, organs with a changed topology, stones,
 * tasks) with the session's records in it: from each tool's session record
 * (session_tool.h) its palpation measures (training/thresholds.h) and tally
 * (tool_metrics.h: grasps, time holding);
 * each tool's role (tool_roles.h: owner, guide, authority, coupling), so an
 * instructor's assignment or take-over outlives a crash. A model that
 * cannot save its changed topology stops the checkpoints: the file keeps
 * the last state that could be saved.
 *
 * The file is untrusted on load: magic and format version (a file of
 * another format is refused, naming both), the state's own checks
 * (checkpoint_state.h), a CRC-32 over everything, the session's records
 * finite and in range; anything else is refused with a message naming the
 * file and what is wrong, and the server starts from rest. Writing is
 * atomic (temporary file, fsync, rename), so a kill during a write leaves
 * the previous checkpoint intact.
 * Allocation: one buffer per save/load, outside the physics step. */
#ifndef VISCERA_CHECKPOINT_H
#define VISCERA_CHECKPOINT_H

#include "runtime/scene_runtime.h"
#include "session/session_tool.h"
#include "session/tool_roles.h"
#include "state_blob.h"
#include "verr.h"

#include <stdint.h>

/* Writes the state of `rt`, the measures of the tools' session records
 * `tools` (rt->ntools of them: tracker and tally) and the tools' roles
 * (`roles`, NULL: none saved; on load NULL ignores the file's) to `path`.
 * -1 with err when it cannot (a model that cannot save its changed
 * topology, out of memory, write error). */
int checkpoint_save(const char *path, const runtime_t *rt, const session_tool_t *tools, const tool_roles_t *roles,
                    verr_t *err);

/* Restores a checkpoint written for the same scene into `rt` and the
 * measures of `tools` (tracker measures and tally; the levels and the rest
 * of each record stay as they are). Returns 1 when restored (organs with a
 * restored topology already followed: runtime_topology_restored), 0 when
 * `path` does not exist (fresh start), -1 with err when the file is
 * unreadable, damaged, of another format or for another scene (rt and
 * tools are then as from rest: unchanged, or rt rebuilt from the scene
 * when a topology restore failed midway), -2 when that rebuild failed too
 * (out of memory: rt is unusable). */
int checkpoint_load(const char *path, runtime_t *rt, session_tool_t *tools, tool_roles_t *roles, verr_t *err);

/* The state a resumed session runs from, for its recording (issue 16:
 * SceneSource.resume_state, so viscera-resim starts where the server did):
 * the core's state (runtime/checkpoint_state.h) with each tool's measures
 * (training/measures_blob.h) and nothing else: no magic, no roles (the
 * recorded AppliedInput carries their effect), no CRC (the recording's
 * transport checks it). Appended to *out (the caller frees out->p); -1 with
 * err as checkpoint_save. */
int checkpoint_resume_state(state_blob_t *out, const runtime_t *rt, const session_tool_t *tools, verr_t *err);

/* Periodic checkpoints from the physics loop without waiting on the disk:
 * submit() copies the state (no allocation once the buffers have grown;
 * a cut organ's topology is serialised too) and a writer thread writes it atomically; a state that cannot be saved
 * is skipped, said once on stderr. stop() writes what is pending,
 * joins the thread and frees it; -1 with err if any write failed. */
typedef struct checkpointer checkpointer_t;
checkpointer_t *checkpointer_start(const char *path, verr_t *err);
void checkpointer_submit(checkpointer_t *c, const runtime_t *rt, const session_tool_t *tools,
                         const tool_roles_t *roles);
int checkpointer_stop(checkpointer_t *c, uint64_t *written, verr_t *err);

#endif
