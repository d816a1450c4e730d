/* SPDX-License-Identifier: Apache-2.0 */
#include "session/session_control.h"

#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene_limits.h"
#include "session/tool_roles.h"

/* Every answer ends with the command's origin, so the station that sent it
 * can tell its own answer from older events it receives as a late joiner. */
static void tag(const viscera_SessionControl *c, char *text, size_t n) {
  size_t len = strlen(text);
  if (len < n) snprintf(text + len, n - len, " [station %" PRIu32 " seq %" PRIu64 "]", c->source_id, c->seq);
}

static int refuse(session_control_t *sc, const viscera_SessionControl *c, char *text, size_t n, const char *why) {
  sc->refused++;
  snprintf(text, n, "SessionControl refused: %s", why);
  tag(c, text, n);
  return -1;
}

/* Thresholds as the scene file accepts them (common/scene.c): each either 0
 * (not set) or inside the table's tools.thresholds range (scene_limits.h),
 * the set ones ordered st < mpf <= sft, none above the tool's clamp (a level
 * the tool can never reach is a mistake). */
static const char *check_levels(const double v[3], double max_force, char *why, size_t n) {
  for (int k = 0; k < 3; k++) {
    if (v[k] == 0) continue;
    if (scene_limit_check("tools.thresholds", v[k], why, n)) return why;
    if (v[k] > max_force) return "threshold above the tool's max_force";
  }
  if (v[0] > 0 && v[1] > 0 && !(v[0] < v[1])) return "need st < mpf";
  if (v[1] > 0 && v[2] > 0 && !(v[1] <= v[2])) return "need mpf <= sft";
  if (v[0] > 0 && v[2] > 0 && !(v[0] < v[2])) return "need st < sft";
  return NULL;
}

int session_control_duplicate(session_control_t *sc, const viscera_SessionControl *c) {
  for (size_t i = 0; i < sc->nstations; i++) {
    if (sc->station[i] != c->source_id) continue;
    if (c->seq <= sc->last_seq[i]) {
      sc->duplicates++;
      return 1;
    }
    sc->last_seq[i] = c->seq;
    return 0;
  }
  size_t slot = sc->nstations;
  if (slot < SESSION_CONTROL_STATIONS) {
    sc->nstations++;
  } else { /* table full: forget the station remembered longest */
    slot = sc->next_evict;
    sc->next_evict = (sc->next_evict + 1) % SESSION_CONTROL_STATIONS;
  }
  sc->station[slot] = c->source_id;
  sc->last_seq[slot] = c->seq;
  return 0;
}

/* New material values (stiffness, damping, home stiffness, mass), each
 * negative = keep, else inside the same range a scene file must respect
 * (scene_limits.h: a mass of 1e-300 kg is refused here as in the file).
 * Returns NULL or what is wrong (in why). */
static const char *edit_material(scene_material_t *m, const double v[4], char *why, size_t n) {
  static const char *const keys[4] = {"organs.material.stiffness", "organs.material.damping",
                                      "organs.material.home_stiffness", "organs.material.mass"};
  for (int k = 0; k < 4; k++) {
    if (isfinite(v[k]) && v[k] < 0) continue; /* keep */
    if (scene_limit_check(keys[k], v[k], why, n)) return why;
  }
  if (v[0] >= 0) m->stiffness = v[0];
  if (v[1] >= 0) m->damping = v[1];
  if (v[2] >= 0) m->home_stiffness = v[2];
  if (v[3] >= 0) m->mass = v[3];
  return NULL;
}

/* Tool roles (tool_roles.h) validate and apply themselves; answered like
 * every other command. */
static int apply_roles(session_control_t *sc, const viscera_SessionControl *c, char *text, size_t n) {
  char what[200];
  if (!sc->roles) return refuse(sc, c, text, n, "this seat does not assign tools");
  if (tool_roles_apply(sc->roles, c, what, sizeof what)) return refuse(sc, c, text, n, what);
  sc->applied++;
  snprintf(text, n, "%s", what);
  tag(c, text, n);
  return 0;
}

/* The task a START_TASK names: by name in `text`, or by index values[0]
 * when text is "". Returns NULL with *idx set, or why not (in why). */
static const char *find_task(const viscera_SessionControl *c, const scene_t *scene, int *idx, char *why, size_t n) {
  if (c->text[0]) {
    for (size_t i = 0; i < scene->ntasks; i++)
      if (!strcmp(scene->tasks[i].name, c->text)) {
        *idx = (int)i;
        return NULL;
      }
    snprintf(why, n, "no task of that name in the scene ('%.40s'; %zu task(s))", c->text, scene->ntasks);
    return why;
  }
  double v = c->values[0];
  if (!isfinite(v) || v != floor(v) || v < 0 || v >= (double)scene->ntasks) return "task index out of range";
  *idx = (int)v;
  return NULL;
}

int session_control_apply(session_control_t *sc, const viscera_SessionControl *c, session_tool_t *tools, size_t ntools,
                          const double *tool_max_force, scene_t *scene, char *text, size_t n) {
  switch (c->kind) {
  case viscera_CONTROL_PAUSE:
    sc->paused = 1;
    sc->applied++;
    snprintf(text, n, "paused");
    tag(c, text, n);
    return 0;
  case viscera_CONTROL_RESUME:
    sc->paused = 0;
    sc->applied++;
    snprintf(text, n, "resumed");
    tag(c, text, n);
    return 0;
  case viscera_CONTROL_SET_THRESHOLDS: {
    if (c->tool_id < 0 || (size_t)c->tool_id >= ntools) return refuse(sc, c, text, n, "tool id out of range");
    const double v[3] = {c->values[0], c->values[1], c->values[2]};
    char why[200];
    const char *bad = check_levels(v, tool_max_force[c->tool_id], why, sizeof why);
    if (bad) return refuse(sc, c, text, n, bad);
    /* New levels, same history: time above, contact time and path so far
     * stay with the trainee. The hysteretic state restarts below every
     * level, so a force already above a new level is reported as crossing
     * it on the next step. */
    thr_tracker_t *t = &tools[c->tool_id].thr;
    for (int k = 0; k < THR_COUNT; k++) {
      t->level[k] = v[k];
      t->above[k] = 0;
    }
    sc->applied++;
    snprintf(text, n, "tool %" PRId32 " thresholds ST %.3g MPF %.3g SFT %.3g N", c->tool_id, v[0], v[1], v[2]);
    tag(c, text, n);
    return 0;
  }
  case viscera_CONTROL_RESET:
    snprintf(text, n, "reset: the scene restarts from rest");
    tag(c, text, n);
    return SESSION_CONTROL_REBUILD;
  case viscera_CONTROL_SET_MATERIAL: {
    if (c->organ_id < 0 || (size_t)c->organ_id >= scene->norgans)
      return refuse(sc, c, text, n, "organ id out of range");
    scene_organ_t *o = &scene->organs[c->organ_id];
    char why[200];
    const char *bad = edit_material(&o->material, c->values, why, sizeof why);
    if (bad) return refuse(sc, c, text, n, bad);
    snprintf(text, n,
             "organ '%s' material: stiffness %.4g N/m, damping %.4g N s/m, home stiffness %.4g N/m, mass %.4g kg",
             o->name, o->material.stiffness, o->material.damping, o->material.home_stiffness, o->material.mass);
    tag(c, text, n);
    return SESSION_CONTROL_REBUILD;
  }
  case viscera_CONTROL_START_TASK: {
    int k = -1;
    char why[96];
    const char *bad = find_task(c, scene, &k, why, sizeof why);
    if (bad) return refuse(sc, c, text, n, bad);
    sc->start_task = k;
    sc->applied++;
    snprintf(text, n, "task '%s' started by the instructor (tool '%s')", scene->tasks[k].name,
             scene->tools[scene->tasks[k].tool].name);
    tag(c, text, n);
    return SESSION_CONTROL_START_TASK;
  }
  case viscera_CONTROL_ASSIGN_TOOL:
  case viscera_CONTROL_GUIDE:
    return apply_roles(sc, c, text, n);
  }
  return refuse(sc, c, text, n, "unknown command kind");
}
