/* SPDX-License-Identifier: Apache-2.0 */
#include "dds/vdds.h"

#include <stdlib.h>
#include <string.h>

#include "dds/vdds_config.h"
#include "dds/vdds_ident.h"
#include "viscera.h"

typedef enum qos_kind { QOS_STATE, QOS_STREAM, QOS_EVENTS, QOS_METRICS, QOS_CONTROL, QOS_LOG } qos_kind_t;

static const struct {
  const char *name;
  const dds_topic_descriptor_t *desc;
  qos_kind_t qos;
  int lease_ms; /* AUTOMATIC liveliness lease, 0 = none (infinite) */
} TOPICS[VT_COUNT] = {
    [VT_SCENE_INFO] = {"viscera_SceneInfo", &viscera_SceneInfo_desc, QOS_STATE},
    [VT_MESH_STATE] = {"viscera_MeshState", &viscera_MeshState_desc, QOS_STATE},
    /* Deltas are cumulative, so keep-last 1 transient-local lets a late joiner
     * draw the current mesh at once instead of waiting for the next frame. */
    [VT_MESH_DELTA] = {"viscera_MeshDelta", &viscera_MeshDelta_desc, QOS_STATE},
    [VT_TOOL_COMMAND] = {"viscera_ToolCommand", &viscera_ToolCommand_desc, QOS_STREAM, VDDS_TOOL_LEASE_MS},
    [VT_CONTACT_FEEDBACK] = {"viscera_ContactFeedback", &viscera_ContactFeedback_desc, QOS_STREAM,
                             VDDS_FEEDBACK_LEASE_MS},
    [VT_SESSION_EVENT] = {"viscera_SessionEvent", &viscera_SessionEvent_desc, QOS_EVENTS},
    [VT_METRICS] = {"viscera_Metrics", &viscera_Metrics_desc, QOS_METRICS},
    [VT_SESSION_CONTROL] = {"viscera_SessionControl", &viscera_SessionControl_desc, QOS_CONTROL},
    [VT_OBJECT_STATE] = {"viscera_ObjectState", &viscera_ObjectState_desc, QOS_STATE},
    [VT_TOOL_METRICS] = {"viscera_ToolMetrics", &viscera_ToolMetrics_desc, QOS_METRICS},
    [VT_TOOL_ROLE] = {"viscera_ToolRole", &viscera_ToolRole_desc, QOS_STATE},
    [VT_APPLIED_INPUT] = {"viscera_AppliedInput", &viscera_AppliedInput_desc, QOS_LOG},
    [VT_SCENE_SOURCE] = {"viscera_SceneSource", &viscera_SceneSource_desc, QOS_STATE},
    [VT_MESH_KEY_CHUNK] = {"viscera_MeshKeyChunk", &viscera_MeshKeyChunk_desc, QOS_STATE},
};

const char *vdds_topic_name(vdds_topic_id_t t) { return t < VT_COUNT ? TOPICS[t].name : "?"; }

static dds_qos_t *make_qos(qos_kind_t k, int lease_ms) {
  dds_qos_t *q = dds_create_qos();
  /* Loss detection (vdds.h): the same lease offered by writers and
   * requested by readers, so they always match. */
  if (lease_ms > 0) dds_qset_liveliness(q, DDS_LIVELINESS_AUTOMATIC, DDS_MSECS(lease_ms));
  switch (k) {
  case QOS_STATE:
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
    break;
  case QOS_STREAM:
    dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
    dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
    break;
  case QOS_EVENTS:
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 64);
    dds_qset_durability_service(q, 0, DDS_HISTORY_KEEP_LAST, 64, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED,
                                DDS_LENGTH_UNLIMITED);
    break;
  case QOS_METRICS:
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
    break;
  case QOS_CONTROL:
    /* Every command counts (pause then resume must both arrive), but a burst
     * from a misbehaving station must not grow memory: keep the last 16 per
     * station. Volatile: commands act when they arrive, never replayed. */
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 16);
    break;
  case QOS_LOG:
    /* Every sample counts (a recording must hold each applied input to
     * re-simulate), at up to 1 kHz: reliable, keep-last 1000 (a second), so
     * neither a recorder stalled by a disk commit loses one nor the writer
     * ever blocks the physics loop (a loss shows as a seq gap); and
     * transient-local, so a recorder whose discovery of the writer came late
     * on a loaded machine still gets the last second of inputs. */
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1000);
    dds_qset_durability_service(q, 0, DDS_HISTORY_KEEP_LAST, 1000, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED,
                                DDS_LENGTH_UNLIMITED);
    break;
  }
  return q;
}

const dds_topic_descriptor_t *vdds_topic_desc(vdds_topic_id_t t) { return TOPICS[t].desc; }

dds_qos_t *vdds_topic_qos(vdds_topic_id_t t) { return make_qos(TOPICS[t].qos, TOPICS[t].lease_ms); }

int vdds_open(vdds_t *v, dds_domainid_t domain, const char *partition, verr_t *err) {
  memset(v, 0, sizeof *v);
  /* The loopback configuration by default; off loopback, DDS Security or
   * an explicit --insecure (vdds_config.h). */
  if (vdds_config_prepare(stderr, "viscera", err)) return -1;
  /* USER_DATA announces role, host and pid (vdds_ident.h), so recorders
   * and operators can tell the participants of a session apart. */
  dds_qos_t *pq = vdds_participant_qos();
  v->participant = dds_create_participant(domain, pq, NULL);
  if (pq) dds_delete_qos(pq);
  if (v->participant < 0)
    return verr_set(err, "DDS: cannot create participant on domain %d: %s (check CYCLONEDDS_URI)", (int)domain,
                    dds_strretcode(v->participant));
  const char *part = partition && *partition ? partition : VDDS_DEFAULT_PARTITION;
  dds_qos_t *q = dds_create_qos();
  dds_qset_partition1(q, part);
  v->publisher = dds_create_publisher(v->participant, q, NULL);
  v->subscriber = dds_create_subscriber(v->participant, q, NULL);
  dds_delete_qos(q);
  if (v->publisher < 0 || v->subscriber < 0) {
    dds_delete(v->participant);
    return verr_set(err, "DDS: cannot create publisher/subscriber in partition '%s'", part);
  }
  for (int t = 0; t < VT_COUNT; t++) {
    dds_qos_t *tq = make_qos(TOPICS[t].qos, TOPICS[t].lease_ms);
    v->topics[t] = dds_create_topic(v->participant, TOPICS[t].desc, TOPICS[t].name, tq, NULL);
    dds_delete_qos(tq);
    /* Optional: DDS Security permissions made by an older deploy/pki.sh do
     * not name the keyframe chunks; their writer and readers then fail to be
     * created, and keyframes go as MeshState only. */
    if (v->topics[t] < 0 && t == VT_MESH_KEY_CHUNK) continue;
    if (v->topics[t] < 0) {
      dds_delete(v->participant);
      return verr_set(err, "DDS: cannot create topic %s: %s", TOPICS[t].name, dds_strretcode(v->topics[t]));
    }
  }
  return 0;
}

void vdds_close(vdds_t *v) {
  if (v->participant > 0) dds_delete(v->participant);
  memset(v, 0, sizeof *v);
}

dds_entity_t vdds_writer(vdds_t *v, vdds_topic_id_t t, verr_t *err) {
  dds_qos_t *q = make_qos(TOPICS[t].qos, TOPICS[t].lease_ms);
  dds_entity_t w = dds_create_writer(v->publisher, v->topics[t], q, NULL);
  dds_delete_qos(q);
  if (w < 0) verr_set(err, "DDS: cannot create writer for %s: %s", TOPICS[t].name, dds_strretcode(w));
  return w;
}

dds_entity_t vdds_reader(vdds_t *v, vdds_topic_id_t t, verr_t *err) { return vdds_reader_listener(v, t, NULL, err); }

dds_entity_t vdds_reader_listener(vdds_t *v, vdds_topic_id_t t, const dds_listener_t *l, verr_t *err) {
  dds_qos_t *q = make_qos(TOPICS[t].qos, TOPICS[t].lease_ms);
  dds_entity_t r = dds_create_reader(v->subscriber, v->topics[t], q, l);
  dds_delete_qos(q);
  if (r < 0) verr_set(err, "DDS: cannot create reader for %s: %s", TOPICS[t].name, dds_strretcode(r));
  return r;
}

#define STATION_TAG "station="

dds_entity_t vdds_writer_station(vdds_t *v, vdds_topic_id_t t, const char *station, verr_t *err) {
  if (!station || !*station) return vdds_writer(v, t, err);
  if (!station_name_valid(station)) {
    verr_set(err, "station name '%.40s' is not 1..%d characters of A-Z a-z 0-9 _ . -", station, VDDS_STATION_MAX - 1);
    return DDS_RETCODE_BAD_PARAMETER;
  }
  char ud[sizeof STATION_TAG + VDDS_STATION_MAX];
  int n = snprintf(ud, sizeof ud, STATION_TAG "%s", station);
  dds_qos_t *q = make_qos(TOPICS[t].qos, TOPICS[t].lease_ms);
  dds_qset_userdata(q, ud, (size_t)n);
  dds_entity_t w = dds_create_writer(v->publisher, v->topics[t], q, NULL);
  dds_delete_qos(q);
  if (w < 0) verr_set(err, "DDS: cannot create writer for %s: %s", TOPICS[t].name, dds_strretcode(w));
  return w;
}

int vdds_station_of_writer(dds_entity_t reader, dds_instance_handle_t pub, char out[VDDS_STATION_MAX]) {
  out[0] = 0;
  dds_builtintopic_endpoint_t *ep = dds_get_matched_publication_data(reader, pub);
  if (!ep) return -1;
  void *ud = NULL;
  size_t sz = 0;
  /* Exactly "station=NAME": a longer or malformed value is someone else's
   * USER_DATA (or an attack) and stays anonymous. */
  if (ep->qos && dds_qget_userdata(ep->qos, &ud, &sz) && ud && sz > strlen(STATION_TAG) &&
      sz < strlen(STATION_TAG) + VDDS_STATION_MAX && memcmp(ud, STATION_TAG, strlen(STATION_TAG)) == 0) {
    char name[VDDS_STATION_MAX];
    size_t len = sz - strlen(STATION_TAG);
    memcpy(name, (const char *)ud + strlen(STATION_TAG), len);
    name[len] = 0;
    if (strlen(name) == len && station_name_valid(name)) memcpy(out, name, len + 1);
  }
  dds_free(ud);
  dds_builtintopic_free_endpoint(ep);
  return 0;
}
