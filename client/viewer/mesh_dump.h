/* SPDX-License-Identifier: Apache-2.0 */
/* mesh_dump: each organ's current reconstructed mesh (keyframe + applied
 * delta) as Wavefront OBJ, for checking what a viewer shows against what the
 * server simulates.
 *
 * One organ: written to `path`. Several: to `path`.<organ id> each. Every
 * file begins with the line
 *   # organ <id> topology <v> keyframe <k> frame <frame_seq>
 * (frame -1 when no delta is applied) and prints positions with %.9g, which
 * round-trips the floats exactly. */
#ifndef VISCERA_VIEWER_MESH_DUMP_H
#define VISCERA_VIEWER_MESH_DUMP_H

#include "view/scene_view.h"
#include "verr.h"

/* Returns the number of files written (0 when no organ has a keyframe), or
 * -1 with err naming the file that failed. */
int mesh_dump_obj(const scene_view_t *sv, const char *path, verr_t *err);

#endif
