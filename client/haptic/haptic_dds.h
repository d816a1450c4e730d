/* SPDX-License-Identifier: Apache-2.0 */
/* haptic_dds: viscera-haptic's side of DDS: the participant, the
 * ToolCommand writer, the ContactFeedback slot, the SceneInfo reader and the
 * guiding slot (ToolRole and the peer station's commands). */
#ifndef VISCERA_HAPTIC_DDS_H
#define VISCERA_HAPTIC_DDS_H

#include <signal.h>

#include <stdatomic.h>

#include "dds/seat_server.h"
#include "dds/vdds.h"
#include "feedback_slot.h"
#include "guide_slot.h"
#include "haptic_options.h"

typedef struct haptic_dds {
  vdds_t dds;
  dds_entity_t w_cmd;   /* ToolCommand, announcing the station */
  dds_entity_t r_fb;    /* ContactFeedback, into slot */
  dds_entity_t r_scene; /* SceneInfo, taken by a listener: the seat's server (seat_server.h) */
  seat_server_t server; /* whose ContactFeedback is believed */
  _Atomic int scenes;   /* SceneInfo samples adopted from the seat's server */
  char scene_name[65];  /* the first adopted scene (written before `scenes` becomes 1) */
  uint32_t scene_tools;
  feedback_slot_t slot; /* the latest contact model and the latency samples */
  guide_slot_t guide;   /* the tool's role and the other station's positions */
} haptic_dds_t;

/* Opens everything for tool o->tool; latency_capacity samples of
 * command->feedback latency are kept. Returns 0, or 1 after a message on
 * stderr (h is then closed as far as it was opened). */
int haptic_dds_open(haptic_dds_t *h, const haptic_options_t *o, size_t latency_capacity);

/* Waits up to o->wait_server s for the server's SceneInfo (says which
 * scene, warns when the tool is not in it). Returns 1 when it came, 0 when
 * not (after a message, unless *stop ended the wait). */
int haptic_dds_wait_scene(haptic_dds_t *h, const haptic_options_t *o, volatile sig_atomic_t *stop);

/* Closes the participant (stopping the listeners) and then the slots. */
void haptic_dds_close(haptic_dds_t *h);

#endif
