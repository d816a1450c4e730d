/* SPDX-License-Identifier: Apache-2.0 */
/* scene_view: what the viewer knows of a running scene, taken from DDS.
 *
 * Subscribes to SceneInfo (organ colours, tool sizes), MeshState and
 * MeshDelta (the organ meshes, see organ_state.h), ToolCommand (tool tip),
 * ContactFeedback (contact, proxy, force) and ObjectState (stones).
 * Keyframes come both as MeshState and as MeshKeyChunk sets
 * (dds/key_chunks.h), which a lossy link delivers sooner; see below. The
 * chunks have two readers: a transient-local one (the writer's history,
 * two round trips after discovery) and a volatile one, which takes the set
 * the server writes again when it sees a new chunk reader (one way).
 * scene_view_poll() takes what has arrived without blocking; the readers are keep-last 1 per instance,
 * so polling at the viewer's pace loses nothing that would be drawn.
 *
 * Every sample is untrusted: ids are bounded to the tables below, numbers
 * must be finite, meshes and deltas are validated. A bad sample (or a bad
 * entry of a SceneInfo) is dropped, counted in `rejected` and described
 * through the log callback; it never changes what is drawn. A tool stops
 * being drawn when its ToolCommand (or ContactFeedback) writer goes away;
 * meshes stay as last received.
 *
 * Whose samples (issue 15.2): MeshState, MeshDelta, ContactFeedback and
 * ObjectState are believed only from the seat's server (seat_server.h:
 * the participant of the SceneInfo writer that claims role "server");
 * until it is known they wait in their readers; the rest are counted in
 * `ignored` and their writers blocked at the readers' gates
 * (dds/vdds_gate.h), which also bound every reader to the tables' ids, so
 * a flood of ids or a forged keyframe neither grows memory nor replaces
 * the server's mesh. Not thread-safe. */
#ifndef VISCERA_VIEWER_SCENE_VIEW_H
#define VISCERA_VIEWER_SCENE_VIEW_H

#include <stdint.h>

#include "dds/key_chunks.h"
#include "dds/seat_server.h"
#include "dds/vdds.h"
#include "dds/vdds_gate.h"
#include "view/organ_state.h"
#include "verr.h"

/* Bounded like the wire contract (viscera.idl MAX_ORGANS, MAX_TOOLS). */
#define SCENE_VIEW_MAX_ORGANS 16
#define SCENE_VIEW_MAX_TOOLS 8
#define SCENE_VIEW_MAX_OBJECTS 8 /* viscera.idl MAX_OBJECTS */

/* Drawing defaults until SceneInfo says otherwise (the scene file's). */
#define SCENE_VIEW_ORGAN_RGB                                                                                           \
  { 0.8f, 0.35f, 0.3f }
#define SCENE_VIEW_TOOL_RADIUS 0.002f  /* m */
#define SCENE_VIEW_TOOL_LENGTH 0.1f    /* m */
#define SCENE_VIEW_TOOL_MAX_FORCE 4.0f /* N */

typedef struct sv_organ {
  int listed; /* named in the current SceneInfo */
  char name[65];
  float rgb[3]; /* linear RGB, 0..1 */
  organ_state_t mesh;
  key_assembly_t chunks; /* the keyframe chunk set being collected */
  int key_from_chunks;   /* the drawn keyframe came as chunks (1) or as MeshState (0) */
} sv_organ_t;

typedef struct sv_tool {
  int listed;
  char name[65];
  float radius, length, max_force; /* m, m, N */
  float st, mpf, sft;              /* N, palpation thresholds; 0 = unset */
  int have_pose;
  float tip[3];     /* m, from ToolCommand */
  int have_contact; /* a ContactFeedback arrived */
  int in_contact;
  float proxy[3]; /* m */
  float force[3]; /* N */
} sv_tool_t;

/* A rigid object (stone) from ObjectState. */
typedef struct sv_object {
  int have;
  float pos[3]; /* m, centre */
  float radius; /* m */
  float rgb[3];
  int held; /* held by a tool */
  int removed;
} sv_object_t;

/* Receives one line describing a rejected sample (no trailing newline). */
typedef void (*scene_view_log_fn)(void *ctx, const char *msg);

typedef struct scene_view {
  vdds_t dds;
  dds_entity_t rd_scene, rd_state, rd_delta, rd_cmd, rd_contact, rd_object, rd_chunk;
  dds_entity_t rd_chunk_live; /* volatile: the set the server writes again when this viewer matched */
  int have_scene;
  char scene_name[65];
  sv_organ_t organs[SCENE_VIEW_MAX_ORGANS];
  sv_tool_t tools[SCENE_VIEW_MAX_TOOLS];
  sv_object_t objects[SCENE_VIEW_MAX_OBJECTS];
  unsigned long rejected;
  unsigned long ignored; /* samples of server topics not from the seat's server */
  seat_server_t server;
  vdds_gate_t gate_state, gate_delta, gate_cmd, gate_contact, gate_object, gate_chunk;
  /* Keyframes (issue 14): each comes twice, as MeshState and as chunks
   * (MeshKeyChunk); the first to arrive is drawn. A second copy with the
   * same content, or an older one by the other path, is skipped. */
  unsigned long keys_from_state, keys_from_chunks, keys_duplicate;
  uint64_t first_key_mono_ns; /* vtime_mono_ns() when the first keyframe was drawn, 0 before */
  scene_view_log_fn log;
  void *log_ctx;
} scene_view_t;

/* Joins `domain` / `partition` (vdds_open) and creates the six readers.
 * log may be NULL. Returns 0, or -1 with err set (nothing left open). */
int scene_view_open(scene_view_t *sv, int domain, const char *partition, scene_view_log_fn log, void *log_ctx,
                    verr_t *err);
void scene_view_close(scene_view_t *sv);

/* Takes every sample available now, without waiting. Returns the number of
 * valid samples taken (accepted or rejected), or -1 with err set when DDS
 * itself fails. */
int scene_view_poll(scene_view_t *sv, verr_t *err);

/* 1 when at least one keyframe is here and every organ the SceneInfo lists
 * has one (or no SceneInfo has arrived: the caller bounds that wait). */
int scene_view_complete(const scene_view_t *sv);
/* 1 when any organ has a keyframe. */
int scene_view_any_keyframe(const scene_view_t *sv);

/* Union of the keyframes' bounds (as published, not deformed); 0, or -1
 * when no keyframe is here. */
int scene_view_key_bounds(const scene_view_t *sv, double bmin[3], double bmax[3]);

/* Newest sim time over the drawn organs (ns), 0 if none; newest applied
 * delta frame_seq, -1 if none. */
uint64_t scene_view_sim_time_ns(const scene_view_t *sv);
long long scene_view_frame_seq(const scene_view_t *sv);

/* The tool the one-tool readouts (CSV, force bar) follow: the lowest id with
 * a pose or contact, or -1. */
int scene_view_primary_tool(const scene_view_t *sv);

#endif
