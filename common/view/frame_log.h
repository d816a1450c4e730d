/* SPDX-License-Identifier: Apache-2.0 */
/* frame_log: the output directory of a viewer run: frame file names and the
 * frames.csv index, one row per written frame.
 *
 * The directory is created (with parents) if missing; frames.csv is started
 * afresh with its header, so a run's index describes that run's frames.
 * Rows are flushed as written, so a process watching the directory (or a
 * viewer killed hard) leaves a complete index of the frames on disk. */
#ifndef VISCERA_VIEWER_FRAME_LOG_H
#define VISCERA_VIEWER_FRAME_LOG_H

#include <stdio.h>

#include "verr.h"

#define FRAME_LOG_HEADER "frame,file,wall_ms,sim_time_s,frame_seq,in_contact,force_n,tool_px,tool_py,proxy_px,proxy_py"

#define FRAME_LOG_DIR_LEN 3072

typedef struct frame_log {
  char dir[FRAME_LOG_DIR_LEN];
  FILE *csv;
  long frames; /* rows written */
} frame_log_t;

/* What one row says. Unknown values: sim_time_s < 0, frame_seq -1, and
 * pixel coordinates with *_known = 0 (written as -1). */
typedef struct frame_row {
  double wall_ms;
  double sim_time_s;
  long long frame_seq;
  int in_contact;
  double force_n;
  int tool_known, proxy_known;
  double tool_px, tool_py, proxy_px, proxy_py;
} frame_row_t;

int frame_log_open(frame_log_t *fl, const char *dir, verr_t *err);
/* Path of the next frame's PNG (DIR/frame_NNNNN.png) into buf. */
int frame_log_next_path(const frame_log_t *fl, char *buf, size_t size, verr_t *err);
/* Appends the row for the frame just written at frame_log_next_path(). */
int frame_log_add(frame_log_t *fl, const frame_row_t *row, verr_t *err);
/* Closes the index; returns -1 with err set if it could not be completed. */
int frame_log_close(frame_log_t *fl, verr_t *err);

#endif
