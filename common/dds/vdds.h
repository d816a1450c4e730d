/* SPDX-License-Identifier: Apache-2.0 */
/* vdds: DDS participant setup and the product's topic/QoS table.
 *
 * One participant per process, one publisher and one subscriber bound to the
 * session partition (e.g. "lab1/seat03"). QoS per topic follows
 * ../ARCHITECTURE: state topics are reliable + transient-local keep-last 1 so
 * late joiners get them; hot topics are keep-last so a writer never blocks
 * the physics loop or the 1 kHz haptic loop. Not thread-safe during setup. */
#ifndef VISCERA_VDDS_H
#define VISCERA_VDDS_H

#include <dds/dds.h>

#include "dds/vdds_ident.h"
#include "station.h"
#include "verr.h"

typedef enum vdds_topic_id {
  VT_SCENE_INFO,
  VT_MESH_STATE,
  VT_MESH_DELTA,
  VT_TOOL_COMMAND,
  VT_CONTACT_FEEDBACK,
  VT_SESSION_EVENT,
  VT_METRICS,
  VT_SESSION_CONTROL,
  VT_OBJECT_STATE,
  VT_TOOL_METRICS,
  VT_TOOL_ROLE,
  VT_APPLIED_INPUT,  /* issue 16: what the server applied, per loop iteration */
  VT_SCENE_SOURCE,   /* issue 16: the scene text, mesh hashes and build identity */
  VT_MESH_KEY_CHUNK, /* issue 14: keyframes in single-datagram chunks (dds/key_chunks.h) */
  VT_COUNT
} vdds_topic_id_t;

typedef struct vdds {
  dds_entity_t participant;
  dds_entity_t publisher;
  dds_entity_t subscriber;
  dds_entity_t topics[VT_COUNT];
} vdds_t;

/* Liveliness leases of the hot tool topics: AUTOMATIC liveliness, so a
 * process that dies (kill -9, crash, pulled cable) is reported lost this long
 * after its last sign of life. Writers at 1 kHz assert liveliness with every
 * sample, idle ones through Cyclone's lease messages (tens of bytes per
 * lease period). A live process whose loop stalls stays alive: the data
 * timeouts (server 0.5 s without commands, haptic client 50 ms without
 * feedback) cover that case.
 * - ToolCommand (haptic client -> server), 150 ms: a false "lost" on a loaded
 *   machine would release the tool and drop a grasp, which breaks the task,
 *   so the lease is three times the longest scheduler stall seen on the
 *   shared 2-core machine (~50 ms), and still well below the 0.5 s timeout.
 * - ContactFeedback (server -> haptic client), 150 ms: a lost server cuts
 *   the force within a tick, which the hand feels as a step, so a false
 *   "lost" is not free: across a site link (100 ms one way, jitter, 10 %
 *   loss, docs/remote.md) a 30 ms lease lapsed 1-3 times per 13 s. Until
 *   the lease runs out the client renders its last model (a local plane,
 *   passive however old), then ramps it out after
 *   CONTACT_RENDER_HOLD_S without samples (client/haptic/contact_render.h). */
#define VDDS_TOOL_LEASE_MS 150
#define VDDS_FEEDBACK_LEASE_MS 150

/* Default partition when none is given. */
#define VDDS_DEFAULT_PARTITION "viscera/local"

/* Creates the participant on `domain` (DDS_DOMAIN_DEFAULT for the config's)
 * and the partitioned publisher/subscriber. */
int vdds_open(vdds_t *v, dds_domainid_t domain, const char *partition, verr_t *err);
void vdds_close(vdds_t *v);

/* Topic name on the wire, e.g. "viscera_MeshDelta". */
const char *vdds_topic_name(vdds_topic_id_t t);
/* The topic's type descriptor, and a new copy of its QoS from the table
 * (the caller deletes it): for readers that need a topic entity of their
 * own (dds/vdds_gate.h). */
const dds_topic_descriptor_t *vdds_topic_desc(vdds_topic_id_t t);
dds_qos_t *vdds_topic_qos(vdds_topic_id_t t);
/* Writer / reader with the table's QoS; negative DDS return code on failure. */
dds_entity_t vdds_writer(vdds_t *v, vdds_topic_id_t t, verr_t *err);
dds_entity_t vdds_reader(vdds_t *v, vdds_topic_id_t t, verr_t *err);
/* Same with a listener (callbacks run on a DDS thread; may be NULL). */
dds_entity_t vdds_reader_listener(vdds_t *v, vdds_topic_id_t t, const dds_listener_t *l, verr_t *err);

/* Stations (idl ToolRole): a ToolCommand writer names the station driving
 * it in its USER_DATA QoS as "station=NAME". NAME must be 1..VDDS_STATION_MAX-1
 * characters of [A-Za-z0-9_.-]; station_name_valid() (station.h) says
 * whether it is. */
#define VDDS_STATION_MAX STATION_NAME_MAX
/* A writer with the table's QoS plus USER_DATA "station=NAME" (NAME NULL or
 * "": no USER_DATA, the anonymous station). An invalid name is refused. */
dds_entity_t vdds_writer_station(vdds_t *v, vdds_topic_id_t t, const char *station, verr_t *err);
/* The station a remote writer matched by `reader` announced: looks up the
 * publication `pub` (a sample's publication_handle) and parses its
 * USER_DATA, which is untrusted: anything that is not exactly
 * "station=NAME" with a valid NAME yields "" (anonymous). Returns 0, or -1
 * (out = "") when the publication is not (or no longer) matched. Costs a
 * lookup in Cyclone's matched-endpoint table: callers cache it per handle. */
int vdds_station_of_writer(dds_entity_t reader, dds_instance_handle_t pub, char out[VDDS_STATION_MAX]);

#endif
