/* SPDX-License-Identifier: Apache-2.0 */
#include "trajectory.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int parse_double(const char **p, double *out) {
  char *end;
  errno = 0;
  *out = strtod(*p, &end);
  if (end == *p) return -1;
  *p = end;
  return 0;
}

int trajectory_load(const char *path, trajectory_t *out, verr_t *err) {
  memset(out, 0, sizeof *out);
  FILE *f = fopen(path, "r");
  if (!f) return verr_set(err, "%s: cannot open: %s", path, strerror(errno));
  size_t cap = 0;
  char line[512];
  int lineno = 0;
  static const char *field[] = {"t", "x", "y", "z"};
  while (fgets(line, sizeof line, f)) {
    lineno++;
    if (!strchr(line, '\n') && !feof(f)) {
      fclose(f);
      trajectory_free(out);
      return verr_set(err, "%s:%d: line longer than %zu characters", path, lineno, sizeof line - 1);
    }
    char *hash = strchr(line, '#');
    if (hash) *hash = 0;
    const char *p = line;
    while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n') p++;
    if (!*p) continue;
    trajectory_sample_t s = {0};
    double v[4];
    for (int k = 0; k < 4; k++) {
      if (parse_double(&p, &v[k]) || !isfinite(v[k])) {
        fclose(f);
        trajectory_free(out);
        return verr_set(err, "%s:%d: field '%s': expected a finite number", path, lineno, field[k]);
      }
    }
    s.t = v[0];
    memcpy(s.pos, v + 1, sizeof s.pos);
    while (*p == ' ' || *p == '\t') p++;
    if (*p && *p != '\r' && *p != '\n') {
      char *end;
      unsigned long b = strtoul(p, &end, 10);
      const char *q = end;
      while (*q == ' ' || *q == '\t' || *q == '\r' || *q == '\n') q++;
      if (end == p || *q || b > 0xffffffffUL) {
        fclose(f);
        trajectory_free(out);
        return verr_set(err, "%s:%d: field 'buttons': expected an integer mask after t x y z", path, lineno);
      }
      s.buttons = (uint32_t)b;
    }
    if (out->n > 0 && !(s.t > out->s[out->n - 1].t)) {
      double prev = out->s[out->n - 1].t;
      fclose(f);
      trajectory_free(out);
      return verr_set(err, "%s:%d: field 't': %g is not after the previous sample's %g", path, lineno, s.t, prev);
    }
    if (out->n == TRAJECTORY_MAX_SAMPLES) {
      fclose(f);
      trajectory_free(out);
      return verr_set(err, "%s:%d: more than %d samples", path, lineno, TRAJECTORY_MAX_SAMPLES);
    }
    if (out->n == cap) {
      cap = cap ? 2 * cap : 64;
      trajectory_sample_t *ns = realloc(out->s, cap * sizeof *ns);
      if (!ns) {
        fclose(f);
        trajectory_free(out);
        return verr_set(err, "%s: out of memory", path);
      }
      out->s = ns;
    }
    out->s[out->n++] = s;
  }
  fclose(f);
  if (out->n == 0) return verr_set(err, "%s: no samples (expected lines of 't x y z [buttons]')", path);
  return 0;
}

void trajectory_free(trajectory_t *tr) {
  free(tr->s);
  memset(tr, 0, sizeof *tr);
}

void trajectory_eval(const trajectory_t *tr, double t, double pos[3], uint32_t *buttons) {
  const trajectory_sample_t *s = tr->s;
  if (t <= s[0].t || tr->n == 1) {
    memcpy(pos, s[0].pos, sizeof s[0].pos);
    *buttons = s[0].buttons;
    return;
  }
  if (t >= s[tr->n - 1].t) {
    memcpy(pos, s[tr->n - 1].pos, sizeof s[0].pos);
    *buttons = s[tr->n - 1].buttons;
    return;
  }
  size_t lo = 0, hi = tr->n - 1; /* s[lo].t <= t < s[hi].t */
  while (hi - lo > 1) {
    size_t mid = (lo + hi) / 2;
    if (s[mid].t <= t)
      lo = mid;
    else
      hi = mid;
  }
  double a = (t - s[lo].t) / (s[hi].t - s[lo].t);
  for (int k = 0; k < 3; k++) pos[k] = s[lo].pos[k] + a * (s[hi].pos[k] - s[lo].pos[k]);
  *buttons = s[lo].buttons;
}

double trajectory_duration(const trajectory_t *tr) { return tr->n ? tr->s[tr->n - 1].t : 0; }
