/* SPDX-License-Identifier: Apache-2.0 */
/* session_control: the instructor's commands to one seat (SessionControl
 * topic, issue 7 roles), validated and applied to the server's state.
 *
 * Who may send them is not decided here: DDS Security access control lets
 * only instructor identities publish SessionControl in a seat's partition
 * (deploy/pki.sh). Everything in a command is still untrusted input: an
 * unknown kind, a tool id out of range, a non-finite or mis-ordered
 * threshold is refused with a reason and changes nothing.
 *
 * Plain data, no networking and no allocation: the server feeds it each
 * command; tests drive it directly. */
#ifndef VISCERA_SESSION_CONTROL_H
#define VISCERA_SESSION_CONTROL_H

#include <stddef.h>
#include <stdint.h>

#include "scene.h"
#include "session/session_tool.h"
#include "viscera.h"

/* Stations remembered for de-duplication; a deployment has a handful of
 * instructor stations, more only cost a forgotten duplicate. */
#define SESSION_CONTROL_STATIONS 16

typedef struct session_control {
  int paused; /* physics and threshold tracking frozen */
  uint64_t applied, refused, duplicates;
  /* Last seq seen per station: a station resends a command until it hears
   * an answer (its first copy may reach only other readers, such as a
   * recorder, before the server's reader has matched), so a copy with a seq
   * not above the last one from that station is dropped. */
  uint32_t station[SESSION_CONTROL_STATIONS];
  uint64_t last_seq[SESSION_CONTROL_STATIONS];
  size_t nstations, next_evict;
  /* Who drives each tool (CONTROL_ASSIGN_TOOL, CONTROL_GUIDE), owned by the
   * server; NULL: those commands are refused. */
  struct tool_roles *roles;
  int start_task; /* the task index the last SESSION_CONTROL_START_TASK names */
} session_control_t;

/* Returns 1 (and does nothing else) when `c` is a resent copy of a command
 * already handled; otherwise remembers its seq and returns 0. */
int session_control_duplicate(session_control_t *sc, const viscera_SessionControl *c);

/* Applies `c` to the seat: pause/resume, or new thresholds for one tool
 * (the levels of tools[tool].thr, the tool's session record of
 * session_tool.h, replaced; its accumulated measures are kept). Tool thresholds are checked like the scene file's:
 * 0 <= st < mpf <= sft <= max_force for those that are non-zero.
 * RESET and SET_MATERIAL need the scene rebuilt, which only the server can
 * do: for them `scene` (the running scene, copied by the caller) is edited
 * (SET_MATERIAL: the organ's material, each value checked like the scene
 * file's) and SESSION_CONTROL_REBUILD is returned; the caller rebuilds from
 * it and reports the outcome (a material the models refuse, e.g. one that
 * needs too many sub-steps, is refused then).
 * Returns 0 when applied, SESSION_CONTROL_REBUILD, or -1 when refused;
 * `text` (size n) says what was done or why not, for the log and a
 * SessionEvent. */
#define SESSION_CONTROL_REBUILD 1
/* START_TASK names a task of `scene` by name (text) or index (values[0]
 * when text is ""): an unknown one is refused; otherwise sc->start_task is
 * set, `text` says "task 'NAME' started by the instructor ..." and
 * SESSION_CONTROL_START_TASK returned: the caller starts (or restarts) the
 * runtime's task (tasks_start) and publishes EVENT_TASK_STARTED with `text`. */
#define SESSION_CONTROL_START_TASK 2
int session_control_apply(session_control_t *sc, const viscera_SessionControl *c, session_tool_t *tools, size_t ntools,
                          const double *tool_max_force, scene_t *scene, char *text, size_t n);

#endif
