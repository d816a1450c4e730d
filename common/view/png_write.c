/* SPDX-License-Identifier: Apache-2.0 */
#include "view/png_write.h"

#include <png.h>
#include <stdio.h>
#include <string.h>

int png_write_rgb(const char *path, int width, int height, const uint8_t *rgb, int bottom_up, verr_t *err) {
  if (width <= 0 || height <= 0 || !rgb) return verr_set(err, "%s: no image to write (%dx%d)", path, width, height);
  char tmp[4096];
  if (snprintf(tmp, sizeof tmp, "%s.tmp", path) >= (int)sizeof tmp) return verr_set(err, "%s: path too long", path);

  png_image img;
  memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  img.width = (png_uint_32)width;
  img.height = (png_uint_32)height;
  img.format = PNG_FORMAT_RGB;
  /* Light zlib settings: about 4x faster encoding for files ~1.5x larger,
   * measured at 640x480 (3 ms vs 14 ms). The viewer shares a 2-core machine
   * with the physics server and writes 10 frames a second. */
  img.flags = PNG_IMAGE_FLAG_FAST;
  /* libpng's simplified API reads a negative stride as a bottom-up buffer. */
  png_int_32 stride = (png_int_32)width * 3;
  if (bottom_up) stride = -stride;
  if (!png_image_write_to_file(&img, tmp, 0, rgb, stride, NULL)) {
    verr_set(err, "%s: cannot write PNG: %s", tmp, img.message);
    png_image_free(&img);
    remove(tmp);
    return -1;
  }
  if (rename(tmp, path) != 0) {
    remove(tmp);
    return verr_set(err, "%s: cannot rename from %s", path, tmp);
  }
  return 0;
}
