/* SPDX-License-Identifier: Apache-2.0 */
#include "window/input_script.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int parse_key(const char *w, input_key_t *k) {
  static const struct {
    const char *name;
    input_key_t key;
  } KEYS[] = {{"w", INPUT_KEY_W}, {"s", INPUT_KEY_S},     {"r", INPUT_KEY_R},          {"space", INPUT_KEY_SPACE},
              {"q", INPUT_KEY_Q}, {"tab", INPUT_KEY_TAB}, {"escape", INPUT_KEY_ESCAPE}};
  if (w[0] >= '1' && w[0] <= '9' && w[1] == 0) {
    *k = (input_key_t)(INPUT_KEY_1 + (w[0] - '1'));
    return 0;
  }
  for (size_t i = 0; i < sizeof KEYS / sizeof KEYS[0]; i++)
    if (strcmp(w, KEYS[i].name) == 0) {
      *k = KEYS[i].key;
      return 0;
    }
  return -1;
}

static int parse_num(const char *w, double lim, double *out) {
  char *end = NULL;
  errno = 0;
  double v = strtod(w, &end);
  if (!*w || *end || errno || !isfinite(v) || fabs(v) > lim) return -1;
  *out = v;
  return 0;
}

/* One line (comment stripped) into e; 0 on success, 1 for a blank line, -1
 * with err naming the problem. */
static int parse_line(char *line, const char *path, int lineno, input_script_event_t *e, verr_t *err) {
  char *w[5];
  int nw = 0;
  for (char *tok = strtok(line, " \t\r\n"); tok; tok = strtok(NULL, " \t\r\n")) {
    if (nw == 5) return verr_set(err, "%s:%d: too many fields", path, lineno);
    w[nw++] = tok;
  }
  if (nw == 0) return 1;
  memset(e, 0, sizeof *e);
  if (parse_num(w[0], 1e6, &e->t) || e->t < 0)
    return verr_set(err, "%s:%d: time '%s': expected seconds 0..1e6", path, lineno, w[0]);
  if (nw < 2) return verr_set(err, "%s:%d: missing event after the time", path, lineno);
  const char *kind = w[1];
  int want = 0;
  if (strcmp(kind, "motion") == 0) {
    e->ev.kind = INPUT_MOTION;
    want = 4;
    if (nw == 4 && (parse_num(w[2], 1e4, &e->ev.dx) || parse_num(w[3], 1e4, &e->ev.dy)))
      return verr_set(err, "%s:%d: motion: expected DX DY in pixels, |value| <= 10000", path, lineno);
  } else if (strcmp(kind, "wheel") == 0) {
    e->ev.kind = INPUT_WHEEL;
    want = 3;
    double n = 0;
    if (nw == 3 && (parse_num(w[2], 1000, &n) || n != floor(n)))
      return verr_set(err, "%s:%d: wheel: expected an integer number of notches, |N| <= 1000", path, lineno);
    e->ev.n = (int)n;
  } else if (strcmp(kind, "key_down") == 0 || strcmp(kind, "key_up") == 0) {
    e->ev.kind = kind[4] == 'd' ? INPUT_KEY_DOWN : INPUT_KEY_UP;
    want = 3;
    if (nw == 3 && parse_key(w[2], &e->ev.key))
      return verr_set(err, "%s:%d: %s: unknown key '%s' (expected w, s, r, space, q, tab, escape or 1..9)", path,
                      lineno, kind, w[2]);
  } else if (strcmp(kind, "button_down") == 0 || strcmp(kind, "button_up") == 0) {
    e->ev.kind = kind[7] == 'd' ? INPUT_BUTTON_DOWN : INPUT_BUTTON_UP;
    want = nw == 4 ? 4 : 2;
    if (nw == 4) {
      if (parse_num(w[2], 1e4, &e->ev.x) || parse_num(w[3], 1e4, &e->ev.y) || e->ev.x < 0 || e->ev.y < 0)
        return verr_set(err, "%s:%d: %s: expected X Y in window pixels, 0..10000", path, lineno, kind);
      e->ev.at = 1;
    }
  } else {
    return verr_set(err, "%s:%d: unknown event '%s' (expected motion, wheel, key_down, key_up, button_down, button_up)",
                    path, lineno, kind);
  }
  if (nw != want) return verr_set(err, "%s:%d: %s takes %d value(s), got %d", path, lineno, kind, want - 2, nw - 2);
  return 0;
}

int input_script_load(const char *path, input_script_t *s, verr_t *err) {
  memset(s, 0, sizeof *s);
  FILE *f = fopen(path, "r");
  if (!f) return verr_set(err, "%s: cannot open: %s", path, strerror(errno));
  size_t cap = 0;
  char line[512];
  int lineno = 0, rc = 0;
  while (fgets(line, sizeof line, f)) {
    lineno++;
    if (!strchr(line, '\n') && !feof(f)) {
      rc = verr_set(err, "%s:%d: line longer than %zu characters", path, lineno, sizeof line - 2);
      break;
    }
    char *hash = strchr(line, '#');
    if (hash) *hash = 0;
    input_script_event_t e;
    int r = parse_line(line, path, lineno, &e, err);
    if (r < 0) {
      rc = -1;
      break;
    }
    if (r > 0) continue;
    if (s->n && e.t < s->ev[s->n - 1].t) {
      rc = verr_set(err, "%s:%d: time %g is before the previous event's %g", path, lineno, e.t, s->ev[s->n - 1].t);
      break;
    }
    if (s->n == cap) {
      if (cap >= 1000000) {
        rc = verr_set(err, "%s:%d: more than 1000000 events", path, lineno);
        break;
      }
      cap = cap ? 2 * cap : 64;
      input_script_event_t *ne = realloc(s->ev, cap * sizeof *ne);
      if (!ne) {
        rc = verr_set(err, "%s: out of memory", path);
        break;
      }
      s->ev = ne;
    }
    s->ev[s->n++] = e;
  }
  if (!rc && ferror(f)) rc = verr_set(err, "%s: read error", path);
  fclose(f);
  if (rc) input_script_free(s);
  return rc;
}

void input_script_free(input_script_t *s) {
  free(s->ev);
  memset(s, 0, sizeof *s);
}

const input_script_event_t *input_script_due(input_script_t *s, double t) {
  if (s->next < s->n && s->ev[s->next].t <= t) return &s->ev[s->next++];
  return NULL;
}

double input_script_duration(const input_script_t *s) { return s->n ? s->ev[s->n - 1].t : 0; }
