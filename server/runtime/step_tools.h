/* SPDX-License-Identifier: Apache-2.0 */
/* step_tools: the runtime's tool phases (interact_*): what tools do
 * besides the god-object contact. Graspers grasp, hold, pull and release
 * tissue (interaction/grasp.h), extractors take and carry stones
 * (interaction/stone.h), tools touch each other, tasks progress
 * (interaction/tasks.h). runtime_step (scene_runtime.c) calls these in its
 * phases:
 *
 *   inputs   interact_inputs: the accepted commands' jaws (button bit 0)
 *            closing or opening since the last step
 *   tools    interact_tools: closing grabs, opening releases; held stones
 *            follow their tool; tools that hold something or have no
 *            tissue contact (extractor) leave the god-object proxy
 *   models   interact_apply, in the model hook, every sub-step: grasp
 *            springs, shaft contact (shaft.h; node test and
 *            segment-triangle crossings via the organ's tree) and stone
 *            penalty forces on the organ's surface
 *   outputs  interact_outputs: each tool's contributions to the force the
 *            hand feels (grasp pull, held stone, stone touch, shaft), what
 *            its client is told (tool_rt_t.fb_*), tool-tool contact (tips
 *            are kept at least the sum of their radii apart by moving both
 *            along the line between them; the tools feel K (tip - device)),
 *            the hand force (interact_hand_force), stone removal, tasks
 *
 * Events (grasp begin/end, task started/completed) go to rt->events. */
#ifndef VISCERA_STEP_TOOLS_H
#define VISCERA_STEP_TOOLS_H

#include "runtime/scene_runtime.h"

/* Stones from the scene's objects; refuses a stone whose centre is not
 * inside its organ's surface (message names the scene line). */
int interact_init(runtime_t *rt, verr_t *err);
void interact_inputs(runtime_t *rt);
void interact_tools(runtime_t *rt);
/* Whether tool t's god-object proxy meets tissue this step. */
int interact_uses_proxy(const runtime_t *rt, size_t t);
void interact_apply(runtime_t *rt, organ_rt_t *o, model_t *m);
void interact_outputs(runtime_t *rt);
/* The feedback part of the outputs phase over the records `tools` (rt->ntools
 * of them, indexed like rt->tools): each tool's contributions, what its
 * client is told (fb_*), tool-tool contact, the hand force. interact_outputs
 * runs it on rt->tools; runtime_feedback_preview on copies, so it reads rt
 * (organs, stones, the scalpel) and writes only `tools` and the culls'
 * working memory (rt->cull's counters, the organs' cull scratch). */
void interact_feedback(runtime_t *rt, tool_rt_t *tools);
/* The tool's client is gone: drop whatever it holds, stop acting (tool
 * inactive, no force). The god-object keeps its contact, so a client back
 * with its hand inside the organ feels it again (docs/remote.md). */
void interact_release_tool(runtime_t *rt, size_t t);

/* The force the hand feels on tool t (tool->force, N) from this step's
 * contributions (tool->from): the only writer of tool->force (the same
 * code writes the force of the preview's copies, interact_feedback). Zero
 * for an inactive tool. Also raises the tool's peak force. */
void interact_hand_force(runtime_t *rt, size_t t);

#endif
