/* SPDX-License-Identifier: Apache-2.0 */
/* measures_blob: one tool's accumulated trainee measures as bytes, the
 * layout a checkpoint keeps per tool (session/checkpoint.c) and the state a
 * resumed session records for its re-simulation (issue 16: SceneSource
 * resume_state, read by server/resim). One layout in one place, so the
 * server and the re-simulation cannot disagree on it.
 *
 * Layout (native byte order, state_blob.h): per threshold level k
 * time_above[k] (f64) and crossings[k] (u64); peak_force, contact_time,
 * contact_force_integral, path_length (f64); grasps (u64), grasp_time (f64).
 * The levels themselves are not saved (they are the scene's, or a
 * control's). Untrusted on read: non-finite or negative measures and a
 * grasp count beyond 32 bits are refused. */
#ifndef VISCERA_MEASURES_BLOB_H
#define VISCERA_MEASURES_BLOB_H

#include <stdint.h>

#include "state_blob.h"
#include "training/thresholds.h"

void measures_blob_put(state_blob_t *b, const thr_tracker_t *tr, uint32_t grasps, double grasp_time);

/* Reads into tr's measures (its levels and live state are kept) and the
 * tally; NULL when good, else what is wrong (then tr and the tally are
 * partly written: the caller reads into copies). */
const char *measures_blob_get(state_blob_t *b, thr_tracker_t *tr, uint32_t *grasps, double *grasp_time);

#endif
