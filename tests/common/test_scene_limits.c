/* SPDX-License-Identifier: Apache-2.0 */
/* test_scene_limits: the one range table (common/scene_limits.c) as the
 * scene parser applies it: the values issue 15 found accepted (mass
 * 1e-300 kg, dt 1e-300 s, stiffness 1e300 N/m) are refused naming file,
 * line, key, value, range and reason; every row's bounds hold at the edge;
 * every row is documented in assets/scenes/README.md "Ranges". */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "scene.h"
#include "scene_limits.h"
#include "test_assets.h"

static scene_t s;
static verr_t e;

#define HEAD "scene: demo\norgans:\n  - name: kidney\n    mesh: k.obj\n"

/* Loading `text` fails and the message holds every one of the parts. */
static int refused(const char *text, const char *const *parts, size_t n) {
  if (scene_load_string(text, "t.yaml", NULL, &s, &e) == 0) {
    fprintf(stderr, "  accepted: %s\n", text);
    return 0;
  }
  for (size_t i = 0; i < n; i++)
    if (!strstr(e.msg, parts[i])) {
      fprintf(stderr, "  '%s' not in: %s\n", parts[i], e.msg);
      return 0;
    }
  return 1;
}

static void test_issue_cases(void) {
  const char *mass[] = {"t.yaml:5:", "organs[0].material.mass'", "(got 1e-300)", ">= 0.001 and <= 20 kg", "gram"};
  CHECK(refused(HEAD "    material: {mass: 1e-300}\n", mass, 5));
  const char *dt[] = {"t.yaml:6:", "physics.dt'", "(got 1e-300)", ">= 1e-05 and <= 0.05 s", "real time"};
  CHECK(refused(HEAD "physics:\n  dt: 1e-300\n", dt, 5));
  const char *k[] = {"t.yaml:5:", "organs[0].material.stiffness'", "(got 1e300)", "<= 1e+07 N/m"};
  CHECK(refused(HEAD "    material: {stiffness: 1e300}\n", k, 4));
  const char *hk[] = {"organs[0].material.home_stiffness'", "(got 1e300)"};
  CHECK(refused(HEAD "    material: {home_stiffness: 1e300}\n", hk, 2));
  const char *pos[] = {"organs[0].position[2]'", "(got 1e30)"};
  CHECK(refused(HEAD "    position: [0, 0, 1e30]\n", pos, 2));
  const char *sb[] = {"organs[0].material.stretch_bend_k'", "(got -1e200)"};
  CHECK(refused(HEAD "    material: {stretch_bend_k: -1e200}\n", sb, 2));
  const char *tgt[] = {"tasks[0].target[0]'", "(got 1e12)"};
  CHECK(refused(HEAD "tools: [{name: p}]\ntasks: [{name: t, kind: palpate_target, tool: p, target: [1e12, 0, 0]}]\n",
                tgt, 2));
}

/* Each row: its bounds are accepted (unless open) and the values just
 * outside refused, through the table's own check. */
static void test_rows(void) {
  size_t n;
  const scene_limit_t *t = scene_limits_table(&n);
  CHECK(n >= 40);
  for (size_t i = 0; i < n; i++) {
    const scene_limit_t *l = &t[i];
    CHECK(scene_limit(l->key) == l);
    CHECK(l->lo < l->hi && l->why && l->why[0]);
    CHECK(scene_limit_ok(l, l->lo) == !l->lo_open);
    CHECK(scene_limit_ok(l, l->hi) == !l->hi_open);
    double below = l->lo - (fabs(l->lo) + 1) * 1e-6, above = l->hi + (fabs(l->hi) + 1) * 1e-6;
    CHECK(!scene_limit_ok(l, below) && !scene_limit_ok(l, above));
    CHECK(scene_limit_ok(l, 0.5 * (l->lo + l->hi)));
    CHECK(!scene_limit_ok(l, NAN) && !scene_limit_ok(l, INFINITY) && !scene_limit_ok(l, -INFINITY));
  }
  char msg[300];
  CHECK(scene_limit_check("organs.material.mass", 1e-300, msg, sizeof msg) == -1);
  CHECK(strstr(msg, "organs.material.mass = 1e-300: must be >= 0.001 and <= 20 kg (") != NULL);
  CHECK(scene_limit_check("organs.material.mass", 0.15, msg, sizeof msg) == 0);
  CHECK(scene_limit_check("no.such.key", 1, msg, sizeof msg) == -1);
}

/* The reference (assets/scenes/README.md, section "Ranges") has a row
 * "| `KEY` | LO | HI | UNIT | ..." for every table row, with the same bounds. */
static void test_documented(void) {
  char path[1100];
  snprintf(path, sizeof path, "%s/assets/scenes/README.md", test_source_dir());
  FILE *f = fopen(path, "rb");
  CHECK(f != NULL);
  if (!f) return;
  static char doc[1 << 18];
  size_t len = fread(doc, 1, sizeof doc - 1, f);
  fclose(f);
  doc[len] = '\0';
  const char *sec = strstr(doc, "\n## Ranges");
  CHECK(sec != NULL);
  if (!sec) return;
  size_t n;
  const scene_limit_t *t = scene_limits_table(&n);
  for (size_t i = 0; i < n; i++) {
    char row[200];
    snprintf(row, sizeof row, "| `%s` | %s%g | %g%s |", t[i].key, t[i].lo_open ? "> " : "", t[i].lo, t[i].hi,
             t[i].hi_open ? " (excl.)" : "");
    if (!strstr(sec, row)) {
      fprintf(stderr, "  not documented: %s\n", row);
      CHECK(!"every range documented");
    }
  }
}

int main(void) {
  test_issue_cases();
  test_rows();
  test_documented();
  return check_report("test_scene_limits");
}
