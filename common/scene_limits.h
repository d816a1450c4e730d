/* SPDX-License-Identifier: Apache-2.0 */
/* scene_limits: the physical range of every numeric scene key and every
 * SessionControl value that edits one, in one table (scene_limits.c), with
 * the reason for each bound.
 *
 * The scene parser (scene.c) and the server's SessionControl (server/session/
 * session_control.c) both refuse a value outside its range through this
 * table, so a file and a live edit accept the same values. The table is
 * documented in assets/scenes/README.md ("Ranges"); test_scene_limits checks
 * that every row is there. A range only bounds one value: combinations (the
 * stable step of a material, the st < mpf <= sft order) are checked where
 * they are known (model creation, scene.c). Keys are the scene paths without
 * list indices: "physics.dt", "organs.material.mass", "tools.stiffness".
 * Read-only data: thread-safe. */
#ifndef VISCERA_SCENE_LIMITS_H
#define VISCERA_SCENE_LIMITS_H

#include <stddef.h>

typedef struct scene_limit {
  const char *key;
  double lo, hi;
  unsigned char lo_open, hi_open; /* 1: the bound itself is refused */
  const char *unit;               /* "" for a plain number */
  const char *why;                /* the reason for the bounds, one clause */
} scene_limit_t;

/* The row for key, or NULL (a programming error: every caller names a row). */
const scene_limit_t *scene_limit(const char *key);
/* The whole table (n rows), for the documentation test. */
const scene_limit_t *scene_limits_table(size_t *n);

/* 1 when v is finite and inside l. */
int scene_limit_ok(const scene_limit_t *l, double v);
/* "must be >= 0.001 and <= 20 kg" into dst. */
void scene_limit_describe(const scene_limit_t *l, char *dst, size_t size);
/* 0 when v is inside; else -1 with "KEY = V: must be ... (reason)" in dst. */
int scene_limit_check(const char *key, double v, char *dst, size_t size);

#endif
