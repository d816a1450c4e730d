/* command_intake: a ToolCommand sample taken from DDS as the simulation
 * core's plain command (runtime/tool_command.h), which the core validates
 * (tool_command_check) before anything is applied. */
#ifndef VISCERA_COMMAND_INTAKE_H
#define VISCERA_COMMAND_INTAKE_H

#include "runtime/tool_command.h"
#include "viscera.h"

/* Copies the fields that drive a tool, unchanged (same precision). */
void command_from_dds(const viscera_ToolCommand *in, tool_cmd_t *out);

#endif
