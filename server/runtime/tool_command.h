/* SPDX-License-Identifier: Apache-2.0 */
/* tool_command: validation of tool commands from outside the core (idl
 * ToolCommand samples from the network, converted by the session:
 * session/command_intake.h). Every field is untrusted: a command with a bad
 * id, a non-finite or absurd position (outside the scene's workspace box), a
 * non-unit quaternion or an invalid force capability is rejected with a
 * reason and never applied. */
#ifndef VISCERA_TOOL_COMMAND_H
#define VISCERA_TOOL_COMMAND_H

#include <stddef.h>
#include <stdint.h>

/* A tool command as the core sees it: the fields of idl ToolCommand that
 * drive a tool, in the wire's precision (float), so the check judges exactly
 * what arrived. */
typedef struct tool_cmd {
  uint32_t tool_id;
  float position[3];    /* m, tool tip in scene frame */
  float orientation[4]; /* unit quaternion w, x, y, z */
  uint32_t buttons;     /* bit 0: primary (grasp/cut) */
  float max_force;      /* N, device capability */
  uint64_t seq, echo;   /* the sender's sequence number and clock (ToolCommand seq, client_mono_ns): not
                           checked, carried to the ContactFeedback that answers the command */
} tool_cmd_t;

/* A command as a tool takes it (runtime_command_tool, scene_runtime.h): a
 * checked tool_cmd_t in the core's precision, or the mix of two stations'
 * commands for a guided tool (session/tool_roles.h). The same record from
 * the side that sent it to the tool's record (tool_rt.h: cmd). */
typedef struct tool_input {
  double pos[3];    /* m, tool tip in scene frame */
  double q[4];      /* unit quaternion w, x, y, z */
  uint32_t buttons; /* bit 0: primary (grasp/cut) */
  double max_force; /* N, device capability */
  uint64_t seq, echo;
} tool_input_t;

typedef enum tool_cmd_verdict {
  TOOLCMD_OK = 0,
  TOOLCMD_BAD_ID,
  TOOLCMD_NONFINITE,
  TOOLCMD_OUT_OF_WORKSPACE,
  TOOLCMD_BAD_ORIENTATION,
  TOOLCMD_BAD_MAX_FORCE,
  TOOLCMD_NOT_ASSIGNED, /* well-formed, but the tool is assigned to another station (tool_roles.h) */
  TOOLCMD_VERDICT_COUNT
} tool_cmd_verdict_t;

typedef struct tool_workspace {
  double min[3], max[3]; /* m; positions outside are absurd */
} tool_workspace_t;

tool_cmd_verdict_t tool_command_check(const tool_cmd_t *c, size_t ntools, const tool_workspace_t *ws);
const char *tool_command_verdict_str(tool_cmd_verdict_t v);

/* The checked command in the core's precision (every float widened exactly). */
void tool_input_from_cmd(const tool_cmd_t *c, tool_input_t *out);

#endif
