/* tool_rt: one tool of the running scene (scene_runtime.h): the command
 * applied to it, its god-object proxy, the force it feels, its contact
 * patch, what it holds and what its client is told. */
#ifndef VISCERA_TOOL_RT_H
#define VISCERA_TOOL_RT_H

#include <stddef.h>
#include <stdint.h>

#include "haptics/proxy.h"
#include "interaction/grasp.h"
#include "scene.h"

#define TOOL_PATCH_MAX 128

typedef struct tool_rt {
  const scene_tool_t *cfg;
  int active;       /* a valid command has been received */
  double device[3]; /* commanded tip, m */
  double max_force; /* N: min(tool, device capability) */
  proxy_t proxy;
  double force[3];   /* N on the tool, last step */
  double peak_force; /* N since start */
  /* Contact patch: the tissue vertices that share the reaction force, with
   * weights summing to 1. A rigid tip presses an area, not three vertices;
   * spreading the load keeps the dent smooth and the contact normal steady. */
  size_t npatch;
  uint32_t patch[TOOL_PATCH_MAX];
  double patch_w[TOOL_PATCH_MAX];
  /* Interactions (runtime/step_tools.c). */
  uint32_t buttons;      /* ToolCommand.buttons, bit 0 = jaws closed */
  uint32_t prev_buttons; /* at the previous step: grasping happens on closing */
  grasp_t grasp;         /* grasper: tissue held */
  int stone;             /* extractor: stone held, or -1 */
  double first_cmd_time; /* s of simulated time of the first command, -1 before */
  double axis[3];        /* unit shaft direction from the tip (command orientation applied to +z) */
  /* What the tool's client is told (ContactFeedback): the tip the hand
   * feels (god-object, stone surface, grasp pull or tool-tool contact),
   * normal and whether anything touches; organ -1 for stones and tools. */
  int fb_contact, fb_organ;
  double fb_pos[3], fb_normal[3];
} tool_rt_t;

#endif
