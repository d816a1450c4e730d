/* SPDX-License-Identifier: Apache-2.0 */
/* resim_scene: the scene viscera-resim re-simulates (issue 16:
 * self-contained recordings).
 *
 * Without a scene file, the recording's own: the SceneSource text, its
 * relative mesh paths resolved against the directory the server read it
 * from, every mesh checked against the digest recorded (a mesh that is
 * missing or not the recorded one is refused, naming it). With a scene
 * file, that file, after naming what differs from the recorded text (the
 * differing lines, by number) and meshes (by digest): a what-if run, judged
 * against the recording all the same. */
#ifndef VISCERA_RESIM_SCENE_H
#define VISCERA_RESIM_SCENE_H

#include <stdio.h>

#include "resim/resim_recording.h"
#include "scene.h"
#include "verr.h"

/* Differences go to `report` (SCENE lines); returns 0 or -1 with err.
 * mesh_dir (may be NULL): where to look, by file name, for a recorded mesh
 * that is not where the server read it (a recording moved to another
 * machine or checkout); a file there counts only with the recorded digest. */
int resim_scene_load(scene_t *sc, const char *path, const char *mesh_dir, const resim_recording_t *rec, FILE *report,
                     verr_t *err);

#endif
