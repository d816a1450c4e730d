/* SPDX-License-Identifier: Apache-2.0 */
/* obj_compare: compares the vertex positions ("v" lines) of two OBJ files and
 * their first comment lines. Prints "vertices=<n> max_diff=<m>" and exits 0 if
 * both have the same vertex count and max |a - b| <= TOL, 1 otherwise.
 * usage: obj_compare A.obj B.obj TOL */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static double *load(const char *path, size_t *n, char *first, size_t first_len) {
  FILE *f = fopen(path, "r");
  if (!f) {
    fprintf(stderr, "obj_compare: cannot open %s\n", path);
    return NULL;
  }
  size_t cap = 1024;
  double *v = malloc(cap * sizeof(double));
  char line[512];
  *n = 0;
  first[0] = 0;
  while (v && fgets(line, sizeof line, f)) {
    if (line[0] == '#' && !first[0]) {
      snprintf(first, first_len, "%.200s", line);
      first[strcspn(first, "\n")] = 0;
    }
    double x, y, z;
    if (line[0] == 'v' && line[1] == ' ' && sscanf(line + 2, "%lf %lf %lf", &x, &y, &z) == 3) {
      if (3 * (*n + 1) > cap) {
        cap *= 2;
        double *nv = realloc(v, cap * sizeof(double));
        if (!nv) {
          free(v);
          v = NULL;
          break;
        }
        v = nv;
      }
      v[3 * *n] = x;
      v[3 * *n + 1] = y;
      v[3 * *n + 2] = z;
      (*n)++;
    }
  }
  fclose(f);
  return v;
}

int main(int argc, char **argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: obj_compare A.obj B.obj TOL\n");
    return 2;
  }
  size_t na, nb;
  char ca[256], cb[256];
  double *a = load(argv[1], &na, ca, sizeof ca), *b = load(argv[2], &nb, cb, sizeof cb);
  double tol = atof(argv[3]);
  if (!a || !b) return 1;
  printf("a: %s\nb: %s\n", ca, cb);
  if (na != nb || na == 0) {
    printf("vertex counts differ or zero: %zu vs %zu\n", na, nb);
    return 1;
  }
  double worst = 0, moved = 0;
  for (size_t i = 0; i < 3 * na; i++) worst = fmax(worst, fabs(a[i] - b[i]));
  printf("vertices=%zu max_diff=%.3g tol=%.3g\n", na, worst, tol);
  (void)moved;
  free(a);
  free(b);
  return worst <= tol ? 0 : 1;
}
