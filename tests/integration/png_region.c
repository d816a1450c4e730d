/* SPDX-License-Identifier: Apache-2.0 */
/* png_region: counts the pixels of a PNG inside a rectangle that are close
 * to a colour, so a test can say "the badge is red" or "the force curve is
 * drawn" without comparing whole images.
 * Prints "match=<n> of <pixels in the rectangle>" (rectangle clipped to the
 * image); exits 2 on bad arguments or an unreadable file.
 * usage: png_region FILE X Y W H R G B TOL   (TOL: max |difference| per channel) */
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv) {
  if (argc != 10) {
    fprintf(stderr, "usage: png_region FILE X Y W H R G B TOL\n");
    return 2;
  }
  long v[8];
  for (int i = 0; i < 8; i++) {
    char *end;
    v[i] = strtol(argv[i + 2], &end, 10);
    if (*end || v[i] < 0 || v[i] > 100000) {
      fprintf(stderr, "png_region: '%s' is not a non-negative integer\n", argv[i + 2]);
      return 2;
    }
  }
  png_image img;
  memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&img, argv[1])) {
    fprintf(stderr, "png_region: %s: %s\n", argv[1], img.message);
    return 2;
  }
  img.format = PNG_FORMAT_RGB;
  unsigned char *buf = malloc(PNG_IMAGE_SIZE(img));
  if (!buf || !png_image_finish_read(&img, NULL, buf, 0, NULL)) {
    fprintf(stderr, "png_region: %s: %s\n", argv[1], img.message);
    free(buf);
    return 2;
  }
  long x1 = v[0] + v[2] < (long)img.width ? v[0] + v[2] : (long)img.width;
  long y1 = v[1] + v[3] < (long)img.height ? v[1] + v[3] : (long)img.height;
  long match = 0, total = 0;
  for (long y = v[1]; y < y1; y++)
    for (long x = v[0]; x < x1; x++) {
      const unsigned char *p = buf + ((size_t)y * img.width + (size_t)x) * 3;
      total++;
      match += labs(p[0] - v[4]) <= v[7] && labs(p[1] - v[5]) <= v[7] && labs(p[2] - v[6]) <= v[7];
    }
  printf("match=%ld of %ld\n", match, total);
  free(buf);
  return 0;
}
