/* SPDX-License-Identifier: Apache-2.0 */
/* command_intake: a ToolCommand sample taken from DDS as the simulation
 * core's plain command (runtime/tool_command.h), which the core validates
 * (tool_command_check) before anything is applied. */
#ifndef VISCERA_COMMAND_INTAKE_H
#define VISCERA_COMMAND_INTAKE_H

#include "runtime/tool_command.h"
#include "viscera.h"

/* Copies the fields that drive a tool, unchanged (same precision). */
void command_from_dds(const viscera_ToolCommand *in, tool_cmd_t *out);

/* What the intake gate (dds/vdds_gate.h) checks a ToolCommand against
 * before DDS stores it: the scene's tools and workspace. Fixed once the
 * reader exists (the gate reads it from DDS receive threads). */
typedef struct command_gate {
  size_t ntools;
  tool_workspace_t workspace;
} command_gate_t;

/* vdds_gate_check_fn for ToolCommand: the tool_cmd_verdict_t of
 * tool_command_check (0 = TOOLCMD_OK); arg is a command_gate_t. */
int command_gate_check(const void *sample, void *arg);

#endif
