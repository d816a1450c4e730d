/* SPDX-License-Identifier: Apache-2.0 */
/* tool_rt: one tool of the running scene (scene_runtime.h), the one record
 * of the tool in the core. Its parts, in the order the step uses them:
 *
 *   cmd        the command as last accepted (runtime_command_tool): its
 *              pos is the commanded tip the step drives (the device
 *              point of haptics/proxy.h), kept nowhere else
 *   mechanics  what the tool does with it: the force limit, the shaft
 *              axis, the jaws, what it holds
 *   contact    its god-object proxy and the tissue patch that shares the
 *              proxy's reaction
 *   hand       the contributions the step's phases produce (proxy spring,
 *              grasp pull, stone, shaft, tool-tool) and the one force the
 *              hand feels, summed by interact_hand_force (step_tools.c,
 *              the only writer of `force`)
 *   feedback   what the tool's client is told (ContactFeedback)
 *
 * The parts are anonymous structs: a field is named as before
 * (tool->max_force, tool->force), the part only groups it. The session keeps
 * what the network adds in its own records, indexed like rt->tools
 * (session/session_tool.h: measures, intake, feedback; session/tool_roles.h:
 * writers, stations, liveliness). */
#ifndef VISCERA_TOOL_RT_H
#define VISCERA_TOOL_RT_H

#include <stddef.h>
#include <stdint.h>

#include "haptics/proxy.h"
#include "interaction/grasp.h"
#include "runtime/tool_command.h"
#include "scene.h"

#define TOOL_PATCH_MAX 128

/* What each phase of a step contributes to the force the hand feels, N
 * (runtime_step's contact and outputs phases fill it; interact_hand_force
 * sums it). Valid for an active tool after a step. */
typedef struct tool_forces {
  double proxy[3];  /* god-object spring at the end of the step (contact phase) */
  double proxy_mag; /* its magnitude, as proxy_spring_force returns it */
  int pull;         /* 1: the tool holds tissue (grasp pull) or a stone (its reaction) */
  int pull_organ;   /* the held organ, -1 for a stone */
  double pull_f[3];
  int touch;         /* 1: an extractor's tip on a stone it does not hold */
  double touch_f[3]; /* K (point on the stone's sphere - tip), unclamped */
  double touch_p[3]; /* that point */
  double touch_n[3]; /* the sphere's outward unit normal there */
  size_t shaft_hits; /* shaft contacts (0: none) */
  int shaft_organ;   /* the first organ the shaft touches */
  double shaft[3];   /* the shaft's reaction */
  int tool_tool;     /* 1: another tool's tip moved this one's (fb_pos) */
} tool_forces_t;

typedef struct tool_rt {
  const scene_tool_t *cfg;
  /* The command as last accepted (runtime_command_tool; runtime_set_* set
   * its parts). cmd.pos is the tool's commanded tip, m: the one copy every
   * phase reads (a release leaves it where it was, like the rest of cmd). */
  tool_input_t cmd;
  struct {                 /* mechanics */
    int active;            /* a valid command has been received */
    double max_force;      /* N: min(tool, device capability) */
    double axis[3];        /* unit shaft direction from the tip (command orientation applied to +z) */
    uint32_t buttons;      /* the command's buttons, bit 0 = jaws closed; 0 after a release */
    uint32_t prev_buttons; /* at the previous step: grasping happens on closing */
    int closing, opening;  /* bit 0's edges this step (the step's inputs phase) */
    grasp_t grasp;         /* grasper: tissue held */
    int stone;             /* extractor: stone held, or -1 */
    double first_cmd_time; /* s of simulated time of the first command, -1 before */
  };
  struct { /* contact */
    proxy_t proxy;
    /* Contact patch: the tissue vertices that share the reaction force,
     * with weights summing to 1. A rigid tip presses an area, not three
     * vertices; spreading the load keeps the dent smooth and the contact
     * normal steady. */
    size_t npatch;
    uint32_t patch[TOOL_PATCH_MAX];
    double patch_w[TOOL_PATCH_MAX];
  };
  struct {              /* the hand */
    tool_forces_t from; /* this step's contributions */
    double force[3];    /* N on the tool, last step: the force the hand feels */
    double peak_force;  /* N since start */
  };
  struct { /* feedback: the tip the hand feels (god-object, stone surface,
            * grasp pull or tool-tool contact), normal and whether anything
            * touches; organ -1 for stones and tools */
    int fb_contact, fb_organ;
    double fb_pos[3], fb_normal[3];
  };
} tool_rt_t;

#endif
