/* SPDX-License-Identifier: Apache-2.0 */
/* png_write: an 8-bit RGB image to a PNG file with libpng.
 *
 * The renderer's rows come bottom-up (OpenGL's origin is the bottom-left
 * corner); PNG rows are top-down, so bottom_up = 1 flips them on the way out.
 * The file appears atomically: it is written as PATH.tmp and renamed, so a
 * process watching the output directory never reads half a frame. */
#ifndef VISCERA_VIEWER_PNG_WRITE_H
#define VISCERA_VIEWER_PNG_WRITE_H

#include <stdint.h>

#include "verr.h"

/* rgb holds width * height * 3 bytes, rows packed. Returns 0, or -1 with err
 * naming the path and libpng's reason. */
int png_write_rgb(const char *path, int width, int height, const uint8_t *rgb, int bottom_up, verr_t *err);

#endif
