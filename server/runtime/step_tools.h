/* step_tools: the runtime's tool phases (interact_*): what tools do
 * besides the god-object contact (issue 4). Graspers grasp, hold, pull and
 * release tissue (interaction/grasp.h), extractors take and carry stones
 * (interaction/stone.h), tools touch each other, tasks progress
 * (interaction/tasks.h). scene_runtime.c calls these at fixed points of its
 * step:
 *
 *   interact_before_step  jaws closing/opening (button bit 0 edges): grab
 *                         or release; held stones follow their tool; tools
 *                         that hold something or have no tissue contact
 *                         (extractor) leave the god-object proxy
 *   interact_apply        in the model hook, every sub-step: grasp springs,
 *                         shaft contact (shaft.h; node test and
 *                         segment-triangle crossings via the organ's tree)
 *                         and stone penalty forces on the organ's surface
 *   interact_after_step   the force each tool feels and what its client is
 *                         told (tool_rt_t.fb_*), tool-tool contact (tips are
 *                         kept at least the sum of their radii apart by
 *                         moving both along the line between them; the
 *                         tools feel K (tip - device)), stone removal,
 *                         tasks
 *
 * Events (grasp begin/end, task started/completed) go to rt->events. */
#ifndef VISCERA_STEP_TOOLS_H
#define VISCERA_STEP_TOOLS_H

#include "runtime/scene_runtime.h"

/* Stones from the scene's objects; refuses a stone whose centre is not
 * inside its organ's surface (message names the scene line). */
int interact_init(runtime_t *rt, verr_t *err);
void interact_before_step(runtime_t *rt);
/* Whether tool t's god-object proxy meets tissue this step. */
int interact_uses_proxy(const runtime_t *rt, size_t t);
void interact_apply(runtime_t *rt, organ_rt_t *o, model_t *m);
void interact_after_step(runtime_t *rt);
/* The tool's client is gone: drop whatever it holds. */
void interact_release_tool(runtime_t *rt, size_t t);

#endif
