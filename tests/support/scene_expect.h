/* SPDX-License-Identifier: Apache-2.0 */
/* scene_expect: the two outcomes the scene-parsing unit tests assert for a
 * YAML text (loaded as "t.yaml"): it loads, or it fails with a message that
 * holds given fragments (file:line, field path, reason). On a mismatch the
 * message is printed, so a failing CHECK says what the parser said.
 * Header-only; the caller owns the (large, best static) scene and error. */
#ifndef VISCERA_SCENE_EXPECT_H
#define VISCERA_SCENE_EXPECT_H

#include <stdio.h>
#include <string.h>

#include "scene.h"

/* 1 when `yaml` (based in /base) fails to load with a message holding `a`
 * and, if given, `b`; else 0 after printing what happened. */
static inline int scene_fails_with(scene_t *s, verr_t *e, const char *yaml, const char *a, const char *b) {
  memset(e, 0, sizeof *e);
  if (scene_load_string(yaml, "t.yaml", "/base", s, e) == 0) {
    fprintf(stderr, "  loaded fine, wanted an error with '%s'\n", a);
    return 0;
  }
  if (!strstr(e->msg, a) || (b && !strstr(e->msg, b))) {
    fprintf(stderr, "  got:  %s\n  want: '%s' and '%s'\n", e->msg, a, b ? b : "");
    return 0;
  }
  return 1;
}

/* 1 when `yaml` (based in base_dir) loads into *s; else 0 after printing
 * the error. */
static inline int scene_loads(scene_t *s, verr_t *e, const char *yaml, const char *base_dir) {
  memset(e, 0, sizeof *e);
  if (scene_load_string(yaml, "t.yaml", base_dir, s, e) == 0) return 1;
  fprintf(stderr, "  unexpected error: %s\n", e->msg);
  return 0;
}

#endif
