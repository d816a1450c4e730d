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

#include "verr.h"

typedef enum vdds_topic_id {
  VT_SCENE_INFO,
  VT_MESH_STATE,
  VT_MESH_DELTA,
  VT_TOOL_COMMAND,
  VT_CONTACT_FEEDBACK,
  VT_SESSION_EVENT,
  VT_METRICS,
  VT_OBJECT_STATE,
  VT_TOOL_METRICS,
  VT_COUNT
} vdds_topic_id_t;

typedef struct vdds {
  dds_entity_t participant;
  dds_entity_t publisher;
  dds_entity_t subscriber;
  dds_entity_t topics[VT_COUNT];
} vdds_t;

/* Default partition when none is given. */
#define VDDS_DEFAULT_PARTITION "viscera/local"

/* Creates the participant on `domain` (DDS_DOMAIN_DEFAULT for the config's)
 * and the partitioned publisher/subscriber. */
int vdds_open(vdds_t *v, dds_domainid_t domain, const char *partition, verr_t *err);
void vdds_close(vdds_t *v);

/* Topic name on the wire, e.g. "viscera_MeshDelta". */
const char *vdds_topic_name(vdds_topic_id_t t);
/* Writer / reader with the table's QoS; negative DDS return code on failure. */
dds_entity_t vdds_writer(vdds_t *v, vdds_topic_id_t t, verr_t *err);
dds_entity_t vdds_reader(vdds_t *v, vdds_topic_id_t t, verr_t *err);
/* Same with a listener (callbacks run on a DDS thread; may be NULL). */
dds_entity_t vdds_reader_listener(vdds_t *v, vdds_topic_id_t t, const dds_listener_t *l, verr_t *err);

/* Parses a domain id string (0..230); -1 on bad input. */
int vdds_parse_domain(const char *s);
/* The default domain of every binary: $VISCERA_DOMAIN if set and non-empty,
 * else 0; -1 with err when the variable is not a domain id. */
int vdds_env_domain(verr_t *err);

#endif
