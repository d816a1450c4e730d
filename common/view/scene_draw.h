/* SPDX-License-Identifier: Apache-2.0 */
/* scene_draw: turns what the viewer knows of the scene into a frame: draw
 * calls for the renderer, and the frames.csv readouts of the same frame
 * (contact, force and where the tool tip and proxy land in the image). */
#ifndef VISCERA_VIEWER_SCENE_DRAW_H
#define VISCERA_VIEWER_SCENE_DRAW_H

#include "view/camera.h"
#include "view/frame_log.h"
#include "view/render.h"
#include "view/scene_view.h"

/* Draws every organ with a keyframe in its SceneInfo colour (deformed by
 * its applied delta) and, when tools is set, every tool with a pose (the
 * contact proxy too while in contact) and the force bar of the primary tool.
 * Returns the image (see render_end), or NULL with err set. */
const uint8_t *scene_draw(render_t *r, const camera_t *cam, const scene_view_t *sv, int tools, verr_t *err);

/* Fills row's scene fields from the primary tool and the organs. */
void scene_draw_readouts(const camera_t *cam, const scene_view_t *sv, frame_row_t *row);

#endif
