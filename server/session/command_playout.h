/* SPDX-License-Identifier: Apache-2.0 */
/* command_playout: one side of a tool's commands, taken from DDS in
 * whatever bunches they arrived in, put into effect one per physics step
 * (issue 17 item 6; docs/numerics.md §11.8).
 *
 * Why: a haptic client and the server each tick at 1 kHz on their own
 * clocks. When the client's commands reach the server close to the moment
 * a step takes them, or cross a link with jitter, one step finds none (the
 * tool stands still for a step) and the next finds two (the tool jumps two
 * ticks' motion, and the older command is never put into effect nor
 * answered: a quarter of them across 2 +- 0.6 ms of jitter,
 * net_command_playout). Holding back at most `depth` commands and putting
 * one into effect per step turns the uneven arrivals into an even tool path
 * with every command answered, at the price of up to `depth` steps of
 * latency while the arrivals are uneven (on loopback, the mean command ->
 * feedback latency over every phase went from 1.08x to 1.17x of its floor
 * with depth 1: docs/numerics.md §11.8). So it is off by default
 * (depth 0) and asked for with viscera-server --command-playout N.
 *
 * The rule, once per step (command_playout_next), after the step's take:
 * - nothing waiting: the command in effect stays (the tool holds);
 * - otherwise the oldest waiting command comes into effect, except when a
 *   command has been left waiting at the end of each of the last
 *   PLAYOUT_CATCHUP_STEPS steps: the arrivals are even again but a step
 *   late, so the oldest is dropped and the next comes into effect (one
 *   two-tick move; the latency the waiting added is given back).
 * - command_playout_push keeps at most depth + 1 waiting (the step's
 *   share and `depth` more): beyond that the oldest is superseded, never
 *   put into effect (a burst after a stall longer than the depth).
 * depth 0 is the server before the playout: the newest command at once.
 *
 * The commands pushed must be in the order their writer sent them (the
 * caller drops older ones: seq). Plain data: no allocation, no locks; the
 * step loop's thread only. */
#ifndef VISCERA_COMMAND_PLAYOUT_H
#define VISCERA_COMMAND_PLAYOUT_H

#include <stddef.h>
#include <stdint.h>

#include "runtime/tool_command.h"

#define PLAYOUT_MAX_DEPTH 8       /* steps a command may wait at most (--command-playout) */
#define PLAYOUT_DEFAULT_DEPTH 0   /* the newest at once: no latency added (docs/numerics.md §11.8) */
#define PLAYOUT_CATCHUP_STEPS 50u /* steps of a command always waiting before one is dropped */

typedef struct command_playout {
  tool_input_t wait[PLAYOUT_MAX_DEPTH + 1]; /* oldest first */
  size_t n;
  size_t carried;        /* of them, waiting since before the last command_playout_next */
  uint32_t waited_steps; /* consecutive step ends with a command still waiting */
  /* Counters since the side was (re)set, for the server's summary. */
  uint64_t delayed;    /* commands that came into effect a step or more after their take */
  uint64_t superseded; /* pushed beyond depth + 1 waiting: never in effect */
  uint64_t caught_up;  /* dropped to give the waiting's latency back */
} command_playout_t;

/* Appends c (checked already: tool_command_check) behind the commands
 * waiting; with more than depth + 1 waiting, drops the oldest. */
void command_playout_push(command_playout_t *p, size_t depth, const tool_input_t *c);

/* The step's command, into *out: 1 when one came into effect (out is
 * set), 0 when none was waiting (out untouched). */
int command_playout_next(command_playout_t *p, tool_input_t *out);

/* Forgets the waiting commands (a new writer, a lost client); keeps the counters. */
void command_playout_clear(command_playout_t *p);

#endif
