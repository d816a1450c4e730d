/* SPDX-License-Identifier: Apache-2.0 */
/* region_work: how much physics a runtime's organs did under regional
 * sleeping (physics/ms_regions.h), for the session's summary.
 *
 * Why: a busy seat's tissue step costs what its awake region costs, and
 * that region's size follows the tool's motion as the commands brought it
 * (a trainee whose commands arrive unevenly drags more tissue awake). Two
 * runs' step times compare only next to the work each did
 * (docs/numerics.md §11.7).
 *
 * Pure reads of the models' counters, since each model was built (a
 * rebuild after a scene change starts them again). Same thread as the
 * runtime. */
#ifndef VISCERA_RUNTIME_REGION_WORK_H
#define VISCERA_RUNTIME_REGION_WORK_H

#include <stdint.h>

#include "runtime/scene_runtime.h"

typedef struct region_work {
  int organs;            /* organs that sleep by regions (mass_spring_surface, symplectic Euler) */
  uint64_t node_updates; /* nodes integrated, summed over their sub-steps and those organs */
  uint64_t block_evals;  /* blocks of 4 springs evaluated, likewise */
} region_work_t;

/* Sums the counters of every organ that sleeps by regions (0 organs: none). */
region_work_t runtime_region_work(const runtime_t *rt);

#endif
