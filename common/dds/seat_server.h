/* SPDX-License-Identifier: Apache-2.0 */
/* seat_server: which participant is this seat's server (issue 15.2), so a
 * client believes server topics (ContactFeedback, MeshState, MeshDelta,
 * ObjectState, Metrics, SessionEvent, ToolMetrics...) from it alone.
 *
 * Identity: the participant of the SceneInfo writer, provided that
 * participant announces role "server" in its USER_DATA (vdds_ident.h), or
 * "replay" (viscera-replay plays a recorded server's part in its domain).
 * The newest such SceneInfo writer wins, so a restarted server (a new
 * participant) is adopted as soon as its SceneInfo arrives. Without DDS
 * Security anyone can claim the role and write SceneInfo, so this keeps
 * out participants that are not (or do not claim to be) the seat's
 * server: an anonymous tool, a viewer, a misconfigured client, a second
 * program on the partition; with `--secure`, the access-control
 * permissions (deploy/pki.sh) decide who may write SceneInfo and the
 * server topics at all, so the role is then backed by a certificate.
 *
 * A writer of a server topic is judged once per publication handle
 * (cached, bounded): SEAT_FROM_SERVER (the adopted server's participant),
 * SEAT_OTHER_SERVER (a participant claiming "server" that is not adopted:
 * perhaps the restarted server whose SceneInfo is on its way; ignored but
 * judged again after the next adoption) or SEAT_NOT_SERVER (never the
 * server: a client may block it for good, dds/vdds_gate.h).
 *
 * Thread-safe (one mutex); the functions call DDS lookups, so they may run
 * in listeners but never inside a topic filter. */
#ifndef VISCERA_SEAT_SERVER_H
#define VISCERA_SEAT_SERVER_H

#include <dds/dds.h>
#include <pthread.h>
#include <stdint.h>

#include "verr.h"
#include "viscera.h"

#define SEAT_SERVER_CACHE 64

typedef enum seat_verdict { SEAT_NOT_SERVER = -1, SEAT_OTHER_SERVER = 0, SEAT_FROM_SERVER = 1 } seat_verdict_t;

/* What the adopted SceneInfo allows a server to send (feedback limits). */
typedef struct seat_limits {
  uint32_t ntools, norgans;
  float tool_stiffness[viscera_MAX_TOOLS]; /* N/m, the proxy spring */
  float tool_max_force[viscera_MAX_TOOLS]; /* N */
  /* m: the tool's shaft length plus its tip radius. A tip is never deeper in
   * tissue than its shaft reaches, so no god-object (the proxy of a
   * ContactFeedback) lies farther from the commanded tip than this. */
  float tool_reach[viscera_MAX_TOOLS];
} seat_limits_t;

typedef struct seat_server {
  pthread_mutex_t lock;
  dds_entity_t r_participants; /* DCPSParticipant: the roles */
  int known;
  dds_guid_t guid;                    /* the adopted server's participant */
  dds_instance_handle_t scene_writer; /* its SceneInfo writer */
  uint32_t generation;                /* +1 per adoption */
  seat_limits_t limits;
  uint64_t adopted, scene_refused; /* adoptions; SceneInfo samples not from a server */
  struct {
    dds_instance_handle_t writer;
    uint32_t generation;
    seat_verdict_t verdict;
  } cache[SEAT_SERVER_CACHE];
  size_t ncache, next_recycle;
} seat_server_t;

/* Reads roles through a DCPSParticipant reader of `participant`. */
int seat_server_open(seat_server_t *s, dds_entity_t participant, verr_t *err);
void seat_server_close(seat_server_t *s);

/* A SceneInfo sample taken from r_scene with `info`: 1 when its writer is
 * (now) the seat's server, adopting it (and the scene's limits) when it is
 * a new one; 0 when not (counted in scene_refused). */
int seat_server_scene(seat_server_t *s, dds_entity_t r_scene, const dds_sample_info_t *info,
                      const viscera_SceneInfo *si);

/* Whether writer `pub` of a sample taken from `reader` is the seat's
 * server. Before any server is adopted: SEAT_OTHER_SERVER for all. */
seat_verdict_t seat_server_from(seat_server_t *s, dds_entity_t reader, dds_instance_handle_t pub);

/* 1 and *out = the adopted scene's limits, or 0 when no server yet. */
int seat_server_limits(seat_server_t *s, seat_limits_t *out);

#endif
