/* SPDX-License-Identifier: Apache-2.0 */
/* session_tool: what the session adds to one tool, the tool's session
 * record, indexed like the core's rt->tools (runtime/tool_rt.h: the tool's
 * one record in the core: command, mechanics, contact, hand force,
 * feedback). One record per tool, beside the core's:
 *
 *   measures   the trainee's palpation measures (training/thresholds.h)
 *              and the tool's tally (tool_metrics.h: grasps, time holding):
 *              what a checkpoint saves of the tool (checkpoint.h) and what
 *              an instructor's SET_THRESHOLDS changes (session_control.h)
 *   intake     when its last command was accepted (the command timeout),
 *              whether it was released for a lost client
 *   feedback   the contact last written in ContactFeedback
 *
 * The writers and stations that drive a tool, and when each was last
 * heard, are the tool's role (session/tool_roles.h: roles.tool[t]), kept
 * with the other tools' roles because a control command edits them as a
 * table and they are published as one. Plain data. */
#ifndef VISCERA_SESSION_TOOL_H
#define VISCERA_SESSION_TOOL_H

#include <stdint.h>

#include "session/tool_metrics.h"
#include "training/thresholds.h"

typedef struct session_tool {
  thr_tracker_t thr;      /* palpation measures and the levels they are judged against */
  tool_tally_t tally;     /* grasps begun, time holding */
  uint64_t last_cmd_mono; /* monotonic ns when its last command was accepted (the command timeout) */
  int lost;               /* released for a lost client (to report its return) */
  int was_contact;        /* the contact last written in ContactFeedback (CONTACT_BEGIN/END) */
  int jumped;             /* this step's command moved the tip more than SESSION_EARLY_JUMP_M */
} session_tool_t;

/* m: a command that moves the tool's tip further than this since the last
 * one it took is answered after the tissue step, not before it. A hand at
 * 1 kHz moves 0.05 mm per command pressing at 5 cm/s; a longer move is
 * commands lost or bunched by a link (issue 14), and the early answer,
 * computed on a surface that has not yet yielded to the jump, stretches the
 * tool's spring by all of it for one step (seen: 1.061 N, then 0.963 N for
 * the same command), which a resting hand feels as an overshoot. */
#define SESSION_EARLY_JUMP_M 2.5e-4

#endif
