/* SPDX-License-Identifier: Apache-2.0 */
/* tool_roles: who drives each tool and where the tool goes when two
 * stations drive it (issue 7 roles; the contract is the comment above
 * `struct ToolRole` in idl/viscera.idl).
 *
 * Per tool: the owner station ("" = any station), the guide station ("" =
 * none), the guide's authority (0..1, 1 = take-over) and the coupling
 * stiffness the two clients render between them, a version that increments
 * on every change, and the latest command from each side (owner side, guide
 * side), with its station, writer and arrival time.
 *
 * - tool_roles_classify() says which side a command from station S belongs
 *   to: the guide's when S is the guide, else the owner's when the owner is
 *   "" or S, else it is rejected (the tool is assigned to someone else).
 * - tool_roles_effective() mixes the two sides: authority * x_guide +
 *   (1 - authority) * x_owner; a side silent for TOOL_ROLE_ABSENT_NS counts
 *   as absent and the other side drives alone; buttons and orientation are
 *   the dominant side's (the guide's when authority >= 0.5); max_force the
 *   smaller of the present sides' (each device renders its own share, the
 *   tool must not push harder than the weaker can stop); the echoed seq and
 *   client time are the owner's when it is present, else the guide's.
 * - tool_roles_apply() validates and applies CONTROL_ASSIGN_TOOL and
 *   CONTROL_GUIDE (untrusted: tool id range, station names, finite
 *   authority in 0..1, coupling stiffness finite and at most the tool's
 *   stiffness) and writes what it did, or why not, for the SessionEvent.
 *
 * Plain data: no DDS calls, no allocation; the server feeds it and tests
 * drive it directly. Station names are checked with station_name_valid(). */
#ifndef VISCERA_TOOL_ROLES_H
#define VISCERA_TOOL_ROLES_H

#include <stddef.h>
#include <stdint.h>

#include "station.h"
#include "runtime/tool_command.h"
#include "session/command_playout.h"
#include "scene.h"
#include "viscera.h"

#define TOOL_ROLE_STATION_MAX 32         /* = VDDS_STATION_MAX (checked in tool_roles.c) */
#define TOOL_ROLE_ABSENT_NS 100000000ull /* 100 ms without a command: the side is absent */
#define TOOL_ROLE_DEFAULT_COUPLING 200.0 /* N/m when a GUIDE asks for <= 0 (capped by the tool's stiffness) */

typedef enum tool_side { TOOL_SIDE_OWNER = 0, TOOL_SIDE_GUIDE = 1, TOOL_SIDE_REJECTED = 2 } tool_side_t;

/* One side of a tool: the command in effect and those waiting for their
 * step (command_playout.h), with the sender of the latest taken. */
typedef struct tool_pose {
  int has;                             /* a command came into effect since the side was (re)set */
  char station[TOOL_ROLE_STATION_MAX]; /* who sent the latest taken ("" anonymous) */
  uint64_t writer;                     /* its writer's publication handle (liveliness) */
  uint64_t mono_ns;                    /* when the latest was taken (server monotonic clock) */
  tool_input_t cmd;                    /* the command in effect (its seq and echo go back in ContactFeedback) */
  command_playout_t playout;           /* taken, waiting for their step */
} tool_pose_t;

typedef struct tool_role {
  char name[SCENE_NAME_LEN]; /* the tool's scene name, for messages */
  char owner[TOOL_ROLE_STATION_MAX], guide[TOOL_ROLE_STATION_MAX];
  double authority, coupling; /* 0 when no guide */
  double max_coupling;        /* N/m, the tool's proxy stiffness: the coupling never exceeds it */
  uint32_t version;
  tool_pose_t side[2]; /* [TOOL_SIDE_OWNER], [TOOL_SIDE_GUIDE] */
} tool_role_t;

typedef struct tool_roles {
  size_t ntools;
  tool_role_t tool[SCENE_MAX_TOOLS];
  uint32_t changed;     /* bit t: tool t's role changed and is not yet published */
  size_t playout_depth; /* steps a command may wait (command_playout.h); PLAYOUT_DEFAULT_DEPTH after init */
  /* The playout's counters of sides since forgotten (command_playout_t). */
  uint64_t delayed, superseded, caught_up;
} tool_roles_t;

/* The command the tool takes now (tool_roles_effective), for
 * runtime_command_tool. */
typedef struct tool_effective {
  tool_input_t cmd;
  int owner_present, guide_present;
} tool_effective_t;

_Static_assert(SCENE_MAX_TOOLS <= 32, "tool_roles_t.changed is a 32-bit mask");

/* Every tool: owner from its scene `station:` ("" when absent), no guide,
 * version 1, no commands; every tool marked changed (to be published). */
void tool_roles_init(tool_roles_t *r, const scene_t *scene);

/* Which side a command from `station` ("" anonymous) for tool t drives.
 * t must be < ntools. */
tool_side_t tool_roles_classify(const tool_roles_t *r, size_t t, const char *station);

/* Keeps command c (already validated by tool_command_check, runtime/tool_command.h) as side's latest
 * taken: it waits for its step (tool_roles_advance). A writer other than
 * the side's last one drops what that one left waiting. */
void tool_roles_note(tool_roles_t *r, size_t t, tool_side_t side, const char *station, uint64_t writer,
                     const tool_cmd_t *c, uint64_t now_ns);

/* 1 when `writer` already gave tool t's side a command with seq >= `seq`
 * (taken, in effect or waiting): this one is older and never applied
 * after it (best effort may deliver out of order). */
int tool_roles_stale(const tool_roles_t *r, size_t t, tool_side_t side, uint64_t writer, uint64_t seq);

/* Once per step, after the step's commands were noted: every side with a
 * command waiting puts the next into effect (command_playout_next).
 * Returns the tools whose command in effect changed (bit t). */
uint32_t tool_roles_advance(tool_roles_t *r);

/* The playout's counters summed over every side, past and present. */
void tool_roles_playout_totals(const tool_roles_t *r, uint64_t *delayed, uint64_t *superseded, uint64_t *caught_up);

/* The mixed pose of tool t at now_ns; returns 0 when neither side is
 * present (nothing to apply), 1 otherwise. */
int tool_roles_effective(const tool_roles_t *r, size_t t, uint64_t now_ns, tool_effective_t *out);

/* The side whose latest command came from `writer`, or -1. */
int tool_roles_side_of_writer(const tool_roles_t *r, size_t t, uint64_t writer);

/* Drops a side's command (its writer was lost): it is absent at once. */
void tool_roles_forget(tool_roles_t *r, size_t t, tool_side_t side);

/* Drops every tool's commands (the scene was reset: tools released);
 * roles are kept and marked changed, to be published again. */
void tool_roles_forget_all(tool_roles_t *r);

/* Applies a CONTROL_ASSIGN_TOOL or CONTROL_GUIDE: 0 applied (text says
 * what changed; the tool's version increments and it is marked changed
 * when anything did), -1 refused (text says why). Other kinds: -1. */
int tool_roles_apply(tool_roles_t *r, const viscera_SessionControl *c, char *text, size_t n);

/* A role read back from a checkpoint (untrusted): 0 when owner is "" or a
 * valid station, guide is "" or a valid station other than the owner, and
 * with a guide the authority is in 0..1 and the coupling in (0, the tool's
 * stiffness]; -1 otherwise. restore() installs a valid one like a control
 * command would (version + 1 and marked changed when it differs; without a
 * guide authority and coupling are 0) and returns -1 for an invalid one. */
int tool_roles_valid(const tool_roles_t *r, size_t t, const char *owner, const char *guide, double authority,
                     double coupling);
int tool_roles_restore(tool_roles_t *r, size_t t, const char *owner, const char *guide, double authority,
                       double coupling);

/* The ToolRole sample of tool t. */
void tool_roles_fill(const tool_roles_t *r, size_t t, uint64_t sim_time_ns, viscera_ToolRole *out);

/* "station 'alice'" or "any station" (owner ""), for messages. */
const char *tool_roles_who(const char *station, char *buf, size_t n);

#endif
