/* SPDX-License-Identifier: Apache-2.0 */
/* scene_check: what `viscera-server --check` adds to validating the scene:
 * whether its step keeps real time, and whether its organs have a plausible
 * size. Both only warn: the scene is valid either way.
 *
 * Cost: every organ's model is stepped SCENE_CHECK_STEPS times at the
 * scene's dt, awake (an organ the trainee touches is stepped whatever its
 * sleep settings) and without tools, on a runtime built with regional
 * sleeping off (the caller's: a cut, a reset or a sweeping tool can wake
 * every node, and at rest a sleeping organ would time as nearly free),
 * timed with the thread's CPU clock: what
 * a step costs when the server has a core, so a loaded machine does not
 * make a scene look slow (its wall time would). The organs' sum is compared
 * with dt: above it, the server runs slower than real time at this dt; the
 * warning names the organ that costs most and what would cheapen it.
 * Contact, grasping and cutting add to this; a sum above
 * SCENE_CHECK_MARGIN of dt is reported as leaving little margin.
 *
 * Size: the largest side of an organ's bounding box (after the scene's
 * scale) outside SCENE_CHECK_MIN_SIZE_M..SCENE_CHECK_MAX_SIZE_M is named:
 * usually a mesh in millimetres (or centimetres) read as metres.
 *
 * The runtime is stepped (its state changes): call it on a runtime that is
 * destroyed afterwards. Single-threaded. */
#ifndef VISCERA_SCENE_CHECK_H
#define VISCERA_SCENE_CHECK_H

#include <stdio.h>

#include "runtime/scene_runtime.h"

#define SCENE_CHECK_STEPS 200
#define SCENE_CHECK_MARGIN 0.8
#define SCENE_CHECK_MIN_SIZE_M 0.005
#define SCENE_CHECK_MAX_SIZE_M 0.5

/* Times the organs' steps; the figures go to `out`, a warning to `warn`.
 * Returns the number of warnings (0 or 1). */
int scene_check_cost(runtime_t *rt, FILE *out, FILE *warn);

/* One warning per organ of implausible size, to `warn`; returns how many. */
int scene_check_sizes(const runtime_t *rt, FILE *warn);

#endif
