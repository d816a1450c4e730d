/* SPDX-License-Identifier: Apache-2.0 */
/* control_deliver: the command reaches every reader of it in the seat, not
 * only the server that answered.
 *
 * viscera-control ends once the seat's server has answered. Under DDS
 * Security each reader is matched on its own, after its own key exchange,
 * so a lab recorder's SessionControl reader may match this writer after the
 * server's did: the volatile sample written before that never reaches it,
 * and the recording lacks the instructor's command (3 of 5 recorded in a
 * secure lab). So, after the answer: while discovery knows a SessionControl
 * reader of this partition (another participant's) that the writer has not
 * matched, wait; a reader matched after the last write gets the command
 * written again (same station and seq: the server drops the copy); then
 * wait for every matched reader's acknowledgement. Bounded by `max_s`. */
#ifndef VISCERA_CONTROL_DELIVER_H
#define VISCERA_CONTROL_DELIVER_H

#include <dds/dds.h>

typedef struct control_deliver {
  dds_entity_t participant, writer;
  dds_entity_t r_subs; /* DCPSSubscription: the readers discovery knows */
  char partition[128];
  int matched_at_write; /* the writer's matched readers at its last write */
} control_deliver_t;

/* Opens the DCPSSubscription reader (before the first write, so discovery
 * has filled it by the answer). 0, or a negative DDS return code. */
int control_deliver_open(control_deliver_t *d, dds_entity_t participant, dds_entity_t writer, const char *partition);

/* Records a write of the command (call after each dds_write). */
void control_deliver_wrote(control_deliver_t *d);

/* After the answer: as above, for at least `min_s` (a reader created in
 * answer to this writer, by a recorder, becomes known) and at most `max_s`.
 * 0 delivered to every known reader, 1 some reader not matched or not
 * acknowledging within max_s (how many in *missing). */
int control_deliver_finish(control_deliver_t *d, const void *sample, double min_s, double max_s, int *missing);

void control_deliver_close(control_deliver_t *d);

#endif
