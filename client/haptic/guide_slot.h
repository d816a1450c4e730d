/* SPDX-License-Identifier: Apache-2.0 */
/* guide_slot: what the 1 kHz loop needs to render the guiding hand
 * (guide_force.h), filled by DDS listeners the way feedback_slot is: the
 * latest ToolRole of our tool and the latest commanded position of every
 * other station driving it (read directly from their ToolCommands, not via
 * the server, so the coupling adds no server hop). The loop copies a
 * snapshot under one short critical section; nothing here allocates after
 * init or blocks the loop.
 *
 * Untrusted input: a ToolRole with a station name that is not a valid
 * station, or numbers outside the contract (guide_role_valid), is refused
 * and counted (the previous role stays: a corrupt sample never couples us
 * to anyone); a ToolCommand with a non-finite position is counted and
 * ignored. Our own writer's samples are not delivered (IGNORELOCAL
 * participant) and would be skipped anyway (publication handle = our
 * writer's instance handle): with one keyed instance per tool the reader
 * sees every writer of the tool.
 *
 * Stations of remote writers come from their USER_DATA
 * (vdds_station_of_writer), looked up once per publication handle on the
 * listener thread and cached in a small table (oldest evicted). At most
 * GUIDE_SLOT_STATIONS stations are remembered (the oldest position is
 * replaced), enough for an owner, a guide and a few spectators. */
#ifndef VISCERA_GUIDE_SLOT_H
#define VISCERA_GUIDE_SLOT_H

#include <dds/dds.h>
#include <pthread.h>
#include <stdint.h>

#include "guide_force.h"
#include "dds/seat_server.h"
#include "dds/vdds.h"
#include "dds/vdds_gate.h"
#include "viscera.h"

#define GUIDE_SLOT_STATIONS 8
#define GUIDE_SLOT_HANDLES 16

typedef struct guide_station_pos {
  char station[GUIDE_STATION_MAX];
  double pos[3];
  uint64_t arrival_mono_ns; /* 0: empty entry */
  double transit_s;         /* smoothed one-way transit of its commands, s; < 0: unknown */
} guide_station_pos_t;

typedef struct guide_handle_station {
  dds_instance_handle_t handle; /* 0: empty entry */
  char station[GUIDE_STATION_MAX];
  uint64_t used;
} guide_handle_station_t;

typedef struct guide_slot {
  pthread_mutex_t lock;
  uint32_t tool_id;
  dds_instance_handle_t own_writer; /* our ToolCommand writer, skipped */
  guide_role_t role;
  uint64_t roles_received, roles_rejected;
  guide_station_pos_t pos[GUIDE_SLOT_STATIONS];
  uint64_t peer_samples, own_samples_skipped, bad_samples;
  /* Listener thread only (no lock needed): publication handle -> station. */
  guide_handle_station_t handles[GUIDE_SLOT_HANDLES];
  uint64_t handle_clock;
  /* The peer ToolCommand reader's gate (dds/vdds_gate.h): only this tool's
   * finite commands take an instance or a place in the history, so a flood
   * of other tool ids or garbage neither grows memory nor evicts the peer. */
  vdds_gate_t gate;
  /* ToolRole: only this tool's, believed from the seat's server alone
   * (issue 15.2; NULL server: from anyone, unit tests). */
  vdds_gate_t role_gate;
  seat_server_t *server;
  uint64_t roles_ignored;
} guide_slot_t;

/* What the loop reads each tick. */
typedef struct guide_view {
  guide_role_t role;
  int have_peer;
  double peer[3];
  double peer_age_s;
  double peer_transit_s; /* the peer's commands' one-way transit (guide_slot_transit), s; < 0: unknown */
  char peer_station[GUIDE_STATION_MAX];
} guide_view_t;

int guide_slot_init(guide_slot_t *s, uint32_t tool_id);
void guide_slot_destroy(guide_slot_t *s);
/* Creates the ToolRole and ToolCommand readers with listeners feeding the
 * slot; own_writer is our ToolCommand writer (its samples are skipped).
 * Returns 0, or -1 with err set. */
int guide_slot_attach(guide_slot_t *s, vdds_t *v, dds_entity_t own_writer, verr_t *err);

/* One command of `station` took transit_s (s) from its writer to us: its
 * source timestamp against our wall clock, so only as good as the two
 * machines' clock agreement (NTP: a few ms). Smoothed per station
 * (GUIDE_TRANSIT_GAIN); values outside (0, GUIDE_TRANSIT_MAX_S) are
 * ignored (clocks apart, or a replayed sample). The guiding coupling damps
 * for twice it when that is more than its own round trip to the server
 * (haptic_loop.c): an instructor beside the server sees its own round trip
 * near zero, but the trainee's commands cross the link. Call after
 * guide_slot_command for the same sample. */
#define GUIDE_TRANSIT_GAIN 0.05
#define GUIDE_TRANSIT_MAX_S 1.0
void guide_slot_transit(guide_slot_t *s, const char *station, double transit_s);

/* Applies one ToolRole (listeners call these; unit tests may too). A role
 * for another tool is ignored (0); a refused one returns -1; else 1. */
int guide_slot_role(guide_slot_t *s, const viscera_ToolRole *r);
/* Forgets the role (the server disposed it or is gone). */
void guide_slot_role_lost(guide_slot_t *s);
/* Records a command position from `station` (not ours) arriving at now;
 * -1 (counted) when the position is not finite. */
int guide_slot_command(guide_slot_t *s, const char *station, const float pos[3], uint64_t now);

/* Snapshot for the loop: the role and the peer's latest position for a
 * client of station own (the most recent among the peer side's stations). */
void guide_slot_read(guide_slot_t *s, const char *own, uint64_t now, guide_view_t *out);

#endif
