/* SPDX-License-Identifier: Apache-2.0 */
/* img_diff: compares two PNG frames (same size) inside a square window and
 * outside it. Prints "window_mean=<v> outside_mean=<v> window_changed=<n>"
 * (mean absolute RGB difference, 0..255; pixels whose difference > 24).
 * usage: img_diff A.png B.png CX CY HALF */
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static unsigned char *load(const char *path, unsigned *w, unsigned *h) {
  png_image img;
  memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&img, path)) {
    fprintf(stderr, "img_diff: %s: %s\n", path, img.message);
    return NULL;
  }
  img.format = PNG_FORMAT_RGB;
  unsigned char *buf = malloc(PNG_IMAGE_SIZE(img));
  if (!buf || !png_image_finish_read(&img, NULL, buf, 0, NULL)) {
    fprintf(stderr, "img_diff: %s: %s\n", path, img.message);
    free(buf);
    return NULL;
  }
  *w = img.width;
  *h = img.height;
  return buf;
}

int main(int argc, char **argv) {
  if (argc != 6) {
    fprintf(stderr, "usage: img_diff A.png B.png CX CY HALF\n");
    return 2;
  }
  unsigned wa, ha, wb, hb;
  unsigned char *a = load(argv[1], &wa, &ha), *b = load(argv[2], &wb, &hb);
  if (!a || !b || wa != wb || ha != hb) {
    fprintf(stderr, "img_diff: images missing or of different sizes\n");
    return 1;
  }
  long cx = atol(argv[3]), cy = atol(argv[4]), half = atol(argv[5]);
  double win = 0, out = 0;
  long nwin = 0, nout = 0, changed = 0;
  for (long y = 0; y < (long)ha; y++)
    for (long x = 0; x < (long)wa; x++) {
      size_t i = ((size_t)y * wa + (size_t)x) * 3;
      int d = abs(a[i] - b[i]) + abs(a[i + 1] - b[i + 1]) + abs(a[i + 2] - b[i + 2]);
      if (labs(x - cx) <= half && labs(y - cy) <= half) {
        win += d / 3.0;
        nwin++;
        if (d / 3 > 24) changed++;
      } else {
        out += d / 3.0;
        nout++;
      }
    }
  printf("window_mean=%.3f outside_mean=%.3f window_changed=%ld\n", nwin ? win / nwin : 0, nout ? out / nout : 0,
         changed);
  free(a);
  free(b);
  return 0;
}
