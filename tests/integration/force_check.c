/* SPDX-License-Identifier: Apache-2.0 */
/* force_check: the haptic client's force log judged by its own ticks (one
 * row per tick) and the trajectory's positions, never by wall-clock windows
 * (issue 15.6), for the failover and fault_tolerance tests.
 *
 * force_check failover FORCE_CSV [KILL_ROW]
 *   The server is killed while the hand presses and restarted while it is
 *   still inside; the hand lifts above LIFT_Z and presses again. Asserts:
 *   the first press felt the organ (>= 100 ticks above 0.1 N); the force
 *   went to exactly zero while the hand was still inside, for >= 10 ticks
 *   in a row (nothing rendered from a dead server); the second press, on
 *   the restarted server, felt the organ again (>= 100 ticks above 0.1 N).
 *   With KILL_ROW (the log's data rows on disk when the server was killed:
 *   stdio buffering makes it at most the ticks done by then), that zero run
 *   starts at or after it: the force did not drop for good before the kill.
 *
 * force_check hold FORCE_CSV FROM_ROW TO_ROW
 *   Ticks FROM_ROW..TO_ROW-1 (data rows, 0-based; the rows written while a
 *   client was killed or stalled): at least 100 of them, >= 75 % with a
 *   force above 0.1 N, and no run of HOLD_MAX_GAP ticks in a row without.
 *   A server blocked by a stalled reader stops its feedback for up to 1 s
 *   per write: about 1000 ticks in a row without force, and most of the
 *   stall. On a machine loaded far beyond its cores (load average 17 on 2
 *   cores, two busy loops beside the test) the client's false "server lost"
 *   blips were seen to zero runs of 9-233 ticks, 5-13 % of the ticks. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LIFT_Z 0.05      /* m: above the kidney (its top is at 0.035 m) */
#define INSIDE_Z 0.03    /* m: pressing */
#define HOLD_MAX_GAP 500 /* ticks in a row without force: a blocked server, not a blip */

typedef struct row {
  double t, z, f;
} row_t;

static row_t *load(const char *path, size_t *n) {
  FILE *fp = fopen(path, "r");
  if (!fp) {
    fprintf(stderr, "force_check: cannot read %s\n", path);
    return NULL;
  }
  size_t cap = 1024;
  row_t *r = malloc(cap * sizeof *r);
  char line[512];
  *n = 0;
  while (r && fgets(line, sizeof line, fp)) {
    double t, x, y, z, fx, fy, fz;
    int c;
    if (sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%d", &t, &x, &y, &z, &fx, &fy, &fz, &c) != 8) continue;
    if (*n == cap) {
      row_t *g = realloc(r, 2 * cap * sizeof *r);
      if (!g) break;
      r = g;
      cap *= 2;
    }
    r[(*n)++] = (row_t){t, z, sqrt(fx * fx + fy * fy + fz * fz)};
  }
  fclose(fp);
  return r;
}

static int failover(const row_t *r, size_t n, size_t kill_row) {
  size_t i = 0, press1 = 0, zero_inside = 0, press2 = 0;
  while (i < n && r[i].f <= 0.1) i++; /* first press begins */
  size_t first = i;
  /* the first lift: the hand leaves the tissue */
  size_t lift = first;
  while (lift < n && r[lift].z <= LIFT_Z) lift++;
  /* The longest run of ticks inside with exactly zero force: the server's
   * death (a restarted server may render again before the lift). */
  size_t run = 0, run_start = 0, best_start = 0;
  for (size_t k = first; k < lift; k++) {
    if (r[k].f > 0.1) press1++;
    if (r[k].z <= INSIDE_Z && r[k].f == 0) {
      if (!run++) run_start = k;
      if (run > zero_inside) zero_inside = run, best_start = run_start;
    } else {
      run = 0;
    }
  }
  for (size_t k = lift; k < n; k++) press2 += r[k].z <= INSIDE_Z && r[k].f > 0.1;
  printf("ticks: %zu logged; first press %zu with force; %zu ticks in a row inside with zero force from tick %zu "
         "(t %.3f s); lift at tick %zu; second press %zu with force\n",
         n, press1, zero_inside, best_start, best_start < n ? r[best_start].t : -1.0, lift, press2);
  int bad = 0;
  if (press1 < 100) bad = fprintf(stderr, "FAIL: the first press was not felt\n");
  if (lift >= n) bad = fprintf(stderr, "FAIL: the hand never lifted\n");
  if (zero_inside < 10)
    bad = fprintf(stderr, "FAIL: the force did not drop to zero while the hand was inside (server killed)\n");
  if (press2 < 100) bad = fprintf(stderr, "FAIL: the second press, on the restarted server, was not felt\n");
  if (zero_inside >= 10 && best_start < kill_row)
    bad = fprintf(stderr, "FAIL: the force dropped for good at tick %zu, before the server was killed (tick >= %zu)\n",
                  best_start, kill_row);
  return bad ? 1 : 0;
}

static int hold(const row_t *r, size_t n, size_t from, size_t to) {
  if (to > n) to = n;
  size_t m = 0, f = 0, run = 0, longest = 0;
  for (size_t k = from; k < to; k++, m++) {
    f += r[k].f > 0.1;
    run = r[k].f > 0.1 ? 0 : run + 1;
    if (run > longest) longest = run;
  }
  printf("ticks %zu..%zu: %zu, with force > 0.1 N: %zu; longest run without: %zu ticks\n", from, to, m, f, longest);
  return m >= 100 && (double)f >= 0.75 * (double)m && longest < HOLD_MAX_GAP ? 0 : 1;
}

int main(int argc, char **argv) {
  size_t n = 0;
  row_t *r = argc >= 3 ? load(argv[2], &n) : NULL;
  int rc = 2;
  if (r && (argc == 3 || argc == 4) && strcmp(argv[1], "failover") == 0)
    rc = failover(r, n, argc == 4 ? strtoul(argv[3], 0, 10) : 0);
  if (r && argc == 5 && strcmp(argv[1], "hold") == 0) rc = hold(r, n, strtoul(argv[3], 0, 10), strtoul(argv[4], 0, 10));
  if (rc == 2)
    fprintf(stderr, "usage: force_check failover FORCE_CSV [KILL_ROW] | force_check hold FORCE_CSV FROM_ROW TO_ROW\n");
  free(r);
  return rc;
}
