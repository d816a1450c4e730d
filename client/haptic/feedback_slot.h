/* feedback_slot: the single-slot latest-value buffer between the DDS receive
 * thread and the 1 kHz haptic loop. A DDS listener validates each
 * ContactFeedback for our tool as it arrives, stamps its arrival time (so the
 * command-to-feedback latency is measured at reception, not at the next
 * tick) and overwrites the slot; the loop copies the newest value. Neither
 * side ever waits for the other longer than one short critical section. */
#ifndef VISCERA_FEEDBACK_SLOT_H
#define VISCERA_FEEDBACK_SLOT_H

#include <dds/dds.h>
#include <pthread.h>
#include <stddef.h>
#include <stdint.h>

#include "contact_model.h"
#include "vdds.h"

typedef struct feedback_slot {
  pthread_mutex_t lock;
  uint32_t tool_id;
  /* Latest accepted value. */
  contact_model_t model;
  uint64_t arrival_mono_ns;
  uint64_t received, rejected;
  /* Latencies (us) from ToolCommand send to feedback arrival; one per new
   * command answered; capacity fixed at init. */
  double *latency_us;
  size_t nlatency, cap;
  uint64_t last_cmd_seq;
} feedback_slot_t;

int feedback_slot_init(feedback_slot_t *s, uint32_t tool_id, size_t latency_capacity);
void feedback_slot_destroy(feedback_slot_t *s);
/* Creates the ContactFeedback reader with a data-available listener feeding
 * the slot; negative on failure (err set). */
dds_entity_t feedback_slot_attach(feedback_slot_t *s, vdds_t *v, verr_t *err);
/* Copies the newest value; returns its arrival time (0: none yet). */
uint64_t feedback_slot_read(feedback_slot_t *s, contact_model_t *out);

#endif
