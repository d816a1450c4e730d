/* SPDX-License-Identifier: Apache-2.0 */
/* events: what the interactions report to whoever runs the runtime (the
 * server turns them into SessionEvents). A small queue the runtime appends
 * to and the server drains; when full, new events are counted and dropped
 * rather than blocking or allocating in the step. */
#ifndef VISCERA_INTERACTION_EVENTS_H
#define VISCERA_INTERACTION_EVENTS_H

#include <stddef.h>
#include <stdint.h>

typedef enum iev_kind {
  IEV_GRASP_BEGIN,
  IEV_GRASP_END,
  IEV_TASK_STARTED,
  IEV_TASK_COMPLETED,
  IEV_CUT_BEGIN, /* runtime/step_cut.h: value = surface vertices when the blade first touched */
  IEV_CUT_END    /* value = topology changes the cut made */
} iev_kind_t;

typedef struct iev {
  iev_kind_t kind;
  int tool;        /* -1 if none */
  int organ;       /* grasped organ, or -1 */
  int object;      /* grasped object (stone), or -1 */
  int task;        /* task index, or -1 */
  double value;    /* grasp: vertices taken; task completed: operation time, s */
  double sim_time; /* s */
} iev_t;

#define IEV_QUEUE_LEN 64

typedef struct iev_queue {
  iev_t ev[IEV_QUEUE_LEN];
  size_t n;
  uint64_t dropped;
} iev_queue_t;

static inline void iev_push(iev_queue_t *q, iev_t e) {
  if (q->n < IEV_QUEUE_LEN)
    q->ev[q->n++] = e;
  else
    q->dropped++;
}

#endif
