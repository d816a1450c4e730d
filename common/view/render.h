/* SPDX-License-Identifier: Apache-2.0 */
/* render: offscreen drawing of organs and tools with OSMesa and fixed-function
 * OpenGL, producing an 8-bit sRGB image.
 *
 * Lighting is computed in linear RGB (scene colours are linear, see
 * viscera.idl) into a 16-bit buffer and encoded to sRGB once per frame, so
 * dark gradients do not band. The frame is drawn supersample x supersample
 * larger and box-filtered down, which smooths edges that OSMesa does not
 * antialias. Two directional lights are fixed to the camera (key from the
 * upper left, a dim cool fill from the right), so shading reads the same in
 * every view. A frame is: render_begin, any number of draw calls, render_end.
 *
 * OSMesa binds one context per thread: use a renderer only from the thread
 * that opened it, and one renderer per thread at a time. */
#ifndef VISCERA_VIEWER_RENDER_H
#define VISCERA_VIEWER_RENDER_H

#include <stddef.h>
#include <stdint.h>

#include "view/camera.h"
#include "verr.h"

/* Eye-space direction towards the key light (unnormalised): up, left, towards
 * the viewer. Tests use it to tell the lit side from the far side. */
#define RENDER_KEY_LIGHT_X (-0.40f)
#define RENDER_KEY_LIGHT_Y 0.80f
#define RENDER_KEY_LIGHT_Z 0.45f

/* Largest width or height accepted, times the supersampling factor this
 * must stay within OSMesa's viewport limit (16384). */
#define RENDER_MAX_SIZE 4096

typedef struct render render_t;

/* Opens an OSMesa context (RGBA, 24-bit depth) and a width x height frame,
 * drawn internally at supersample (1..4) times the size. Returns 0, or -1
 * with err set when the size is out of range, memory is short or OSMesa
 * cannot create or bind the context. */
int render_open(render_t **out, int width, int height, int supersample, verr_t *err);
void render_close(render_t *r);

/* Clears to the background gradient and loads the camera's matrices. The
 * camera's size must be the renderer's (it projects in output pixels). */
void render_begin(render_t *r, const camera_t *cam);

/* Draws an indexed triangle mesh in linear colour rgb, lit and smooth
 * shaded with area-weighted vertex normals recomputed from pos now (so a
 * deformed mesh is shaded by its current shape). pos holds 3 * nverts
 * floats; tris 3 * ntris indices, each < nverts (out-of-range triangles are
 * skipped by the normals but must not reach the GL: the caller validates).
 * Returns 0, or -1 with err set when scratch memory cannot grow. */
int render_mesh(render_t *r, const float *pos, size_t nverts, const uint32_t *tris, size_t ntris, const float rgb[3],
                verr_t *err);

/* A probe: a sphere of tip_radius at tip and a shaft of length up +z (the
 * probe comes from above), grey, or yellow while in contact. Parts hidden
 * behind what is already drawn show through faintly, so draw organs first. */
void render_tool(render_t *r, const float tip[3], float tip_radius, float length, int in_contact);

/* A small green sphere marking the contact proxy (god-object) point; its
 * hidden part shows through faintly like the tool's. */
void render_proxy(render_t *r, const float p[3], float radius);
/* A rigid object (a stone): a sphere in its colour, ghosted where tissue
 * hides it, since a stone inside an organ is what the trainee looks for. */
void render_object(render_t *r, const float centre[3], float radius, const float rgb[3]);

/* Overlay: a vertical bar at the right edge filled to force / max_force,
 * green, then yellow above half, red above 80 %, with 1 N ticks when they
 * are not too dense. Draw it last. */
void render_force_bar(render_t *r, double force, double max_force);

/* The same bar with the tool's palpation thresholds (docs/methods.md B ch. 6), N,
 * 0 = unset: a line across the bar at each level set; when ST or MPF is
 * set the fill is green below ST, orange above ST and red above MPF
 * instead of the fraction-of-max colours. */
void render_force_bar_levels(render_t *r, double force, double max_force, double st, double mpf, double sft);

/* Finishes the frame and returns width * height * 3 sRGB bytes, rows
 * bottom-up (OpenGL order). Owned by the renderer; valid until the next
 * render_begin or render_close. */
const uint8_t *render_end(render_t *r);

#endif
