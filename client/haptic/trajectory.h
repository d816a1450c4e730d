/* SPDX-License-Identifier: Apache-2.0 */
/* trajectory: a scripted tool path read from a text file.
 *
 * Format: one sample per line, `t x y z [buttons]` (seconds, metres, integer
 * button mask); '#' starts a comment; blank lines are ignored. Times must be
 * finite and strictly increasing, coordinates finite. Between samples the
 * position is interpolated linearly; before the first and after the last it
 * holds. Errors name the file, line and field. */
#ifndef VISCERA_TRAJECTORY_H
#define VISCERA_TRAJECTORY_H

#include <stddef.h>
#include <stdint.h>

#include "verr.h"

#define TRAJECTORY_MAX_SAMPLES 1000000

typedef struct trajectory_sample {
  double t;
  double pos[3];
  uint32_t buttons;
} trajectory_sample_t;

typedef struct trajectory {
  size_t n;
  trajectory_sample_t *s;
} trajectory_t;

int trajectory_load(const char *path, trajectory_t *out, verr_t *err);
void trajectory_free(trajectory_t *tr);
/* Position and buttons at time t (seconds from the start). */
void trajectory_eval(const trajectory_t *tr, double t, double pos[3], uint32_t *buttons);
/* Time of the last sample. */
double trajectory_duration(const trajectory_t *tr);

#endif
