/* tool_input: validation of ToolCommand samples from the network.
 * Every field is untrusted: a sample with a bad id, a non-finite or absurd
 * position (outside the scene's workspace box), a non-unit quaternion or an
 * invalid force capability is rejected with a reason and never applied. */
#ifndef VISCERA_TOOL_INPUT_H
#define VISCERA_TOOL_INPUT_H

#include <stddef.h>

#include "viscera.h"

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

tool_cmd_verdict_t tool_command_check(const viscera_ToolCommand *c, size_t ntools, const tool_workspace_t *ws);
const char *tool_command_verdict_str(tool_cmd_verdict_t v);

#endif
