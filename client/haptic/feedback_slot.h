/* SPDX-License-Identifier: Apache-2.0 */
/* feedback_slot: the single-slot latest-value buffer between the DDS receive
 * thread and the 1 kHz haptic loop. A DDS listener validates each
 * ContactFeedback for our tool as it arrives, stamps its arrival time (so the
 * command-to-feedback latency is measured at reception, not at the next
 * tick) and overwrites the slot; the loop copies the newest value. Neither
 * side ever waits for the other longer than one short critical section.
 *
 * Latency counts only echoes of our own commands: with two stations on one
 * tool (guiding hand) the server echoes the owner's seq and send time, which
 * the guide's client must not take for its own round trip. The loop notes
 * each command it sends (feedback_slot_sent: seq -> send time in a ring of
 * FEEDBACK_SENT_RING atomics, no lock); an echo counts when its pair
 * matches, i.e. for round trips shorter than the ring (1 s at 1 kHz).
 *
 * Server loss: the same reader's liveliness-changed listener sees the
 * server's ContactFeedback writer lose its liveliness (lease
 * VDDS_FEEDBACK_LEASE_MS, vdds.h) when the server process dies, and clears
 * the slot's contact at once, so the loop renders zero force from its next
 * tick on; the loop asks feedback_slot_server_lost to report it.
 *
 * Whose feedback (issue 15.2): with a seat_server attached, only the seat's
 * server's samples are used; the rest are counted (`ignored`) and their
 * writers blocked at the reader's gate (dds/vdds_gate.h: only this tool's
 * instance exists at all), and their liveliness does not count as the
 * server's. A sample whose stiffness or force exceeds what the adopted
 * scene gives the tool, or (an echo of our own command) whose proxy lies
 * farther from the tip we sent than the tool reaches, is refused
 * (`out_of_limits`). Order (issue 14.2):
 * a sample whose seq is not above the last one taken from the same writer
 * is never used after it (`stale`). */
#ifndef VISCERA_FEEDBACK_SLOT_H
#define VISCERA_FEEDBACK_SLOT_H

#include <dds/dds.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "contact_model.h"
#include "dds/seat_server.h"
#include "dds/vdds.h"
#include "dds/vdds_gate.h"
#include "viscera.h"

#define FEEDBACK_SENT_RING 1024

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
  uint64_t foreign_echoes;                           /* feedback answering another station's command */
  _Atomic uint64_t sent_mono_ns[FEEDBACK_SENT_RING]; /* by seq % ring */
  _Atomic float sent_pos[FEEDBACK_SENT_RING][3];     /* m, the tip sent with it (NaN: not known) */
  /* Liveliness of the server's feedback writer(s). */
  uint32_t writers_alive;
  int server_lost;            /* every writer lost its liveliness */
  uint64_t lost_mono_ns;      /* when the listener heard of it */
  uint64_t lost_last_arrival; /* arrival of the last feedback before that */
  uint64_t lost_events, regained_events;
  /* Whose feedback and which values (issue 15.2), and its order (14.2). */
  seat_server_t *server; /* NULL: every writer is believed (unit tests) */
  vdds_gate_t gate;
  float max_stiffness, max_force; /* the scene's for this tool; 0 = not known */
  float max_reach;                /* m, proxy to commanded tip (seat_limits_t.tool_reach); 0 = not known */
  uint64_t ignored, out_of_limits, stale;
  int32_t nonserver_alive;           /* alive feedback writers that are not the server */
  dds_instance_handle_t last_writer; /* the writer of the last sample taken, and its seq */
  uint64_t last_seq;
} feedback_slot_t;

int feedback_slot_init(feedback_slot_t *s, uint32_t tool_id, size_t latency_capacity);
void feedback_slot_destroy(feedback_slot_t *s);
/* Creates the ContactFeedback reader with a data-available listener feeding
 * the slot; negative on failure (err set). */
dds_entity_t feedback_slot_attach(feedback_slot_t *s, vdds_t *v, verr_t *err);
/* The loop sent command `seq` at client_mono_ns (lock-free). */
void feedback_slot_sent(feedback_slot_t *s, uint64_t seq, uint64_t client_mono_ns);
/* The same with the tip it commanded (m): an echo of it is then also
 * checked against max_reach (feedback_slot_set_reach). */
void feedback_slot_sent_at(feedback_slot_t *s, uint64_t seq, uint64_t client_mono_ns, const double pos[3]);
/* Applies one ContactFeedback arriving at now (the listener calls this;
 * tests may too): -1 refused (not finite, or beyond the limits), 0 another
 * tool's, 1 taken. */
int feedback_slot_accept(feedback_slot_t *s, const viscera_ContactFeedback *fb, uint64_t now);
/* The same for a sample of `writer` (its publication handle): -2 when its
 * seq is not above the last one taken from that writer (never used after
 * a newer one). */
int feedback_slot_accept_from(feedback_slot_t *s, const viscera_ContactFeedback *fb, dds_instance_handle_t writer,
                              uint64_t now);
/* The scene's stiffness and force maxima for this tool (0: unknown). */
void feedback_slot_set_limits(feedback_slot_t *s, float max_stiffness, float max_force);
/* The scene's reach for this tool (m, 0: unknown): an echo of our own
 * command whose proxy lies farther than this from the tip we sent is
 * refused (`out_of_limits`). */
void feedback_slot_set_reach(feedback_slot_t *s, float max_reach);
/* Copies the newest value; returns its arrival time (0: none yet). */
uint64_t feedback_slot_read(feedback_slot_t *s, contact_model_t *out);
/* 1 while the server is lost by liveliness (its feedback writer's lease
 * expired and no writer is alive); then *lost_ns is when that was heard and
 * *last_arrival the arrival of the last feedback before it (0: none). */
int feedback_slot_server_lost(feedback_slot_t *s, uint64_t *lost_ns, uint64_t *last_arrival);
/* Applies a liveliness status (the listener calls this; tests may too). */
void feedback_slot_liveliness(feedback_slot_t *s, const dds_liveliness_changed_status_t *st, uint64_t now);

#endif
