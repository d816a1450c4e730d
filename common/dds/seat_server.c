/* SPDX-License-Identifier: Apache-2.0 */
#include "dds/seat_server.h"

#include <string.h>

#include "dds/vdds_ident.h"

int seat_server_open(seat_server_t *s, dds_entity_t participant, verr_t *err) {
  memset(s, 0, sizeof *s);
  pthread_mutex_init(&s->lock, NULL);
  /* Cyclone serves the built-in topic from its discovery cache: every
   * participant known now and later, kept (read, never taken). */
  s->r_participants = dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSPARTICIPANT, NULL, NULL);
  if (s->r_participants < 0)
    return verr_set(err, "DDS: cannot read DCPSParticipant: %s", dds_strretcode(s->r_participants));
  return 0;
}

void seat_server_close(seat_server_t *s) { pthread_mutex_destroy(&s->lock); }

/* 1 when the participant of endpoint ep announces role "server", or
 * "replay" (viscera-replay stands in for the recorded server in its domain). */
static int claims_server(seat_server_t *s, const dds_builtintopic_endpoint_t *ep) {
  dds_builtintopic_participant_t key;
  memset(&key, 0, sizeof key);
  memcpy(key.key.v, ep->participant_key.v, sizeof key.key.v);
  dds_instance_handle_t ih = dds_lookup_instance(s->r_participants, &key);
  if (!ih) ih = ep->participant_instance_handle;
  void *buf[1] = {NULL};
  dds_sample_info_t si;
  int n = dds_read_instance(s->r_participants, buf, &si, 1, 1, ih);
  int yes = 0;
  if (n > 0 && si.valid_data) {
    const dds_builtintopic_participant_t *p = buf[0];
    void *ud = NULL;
    size_t sz = 0;
    if (p->qos && dds_qget_userdata(p->qos, &ud, &sz) && ud) {
      char ident[VDDS_IDENT_MAX], role[VDDS_ROLE_MAX];
      vdds_ident_sanitize(ident, sizeof ident, ud, sz);
      yes = vdds_ident_role(ident, role, sizeof role) == 0 &&
            (strcmp(role, "server") == 0 || strcmp(role, "replay") == 0);
    }
    dds_free(ud);
  }
  if (n > 0) dds_return_loan(s->r_participants, buf, n);
  return yes;
}

static void limits_from(seat_limits_t *l, const viscera_SceneInfo *si) {
  memset(l, 0, sizeof *l);
  l->norgans = si->organs._length;
  l->ntools = si->tools._length < viscera_MAX_TOOLS ? si->tools._length : viscera_MAX_TOOLS;
  for (uint32_t t = 0; t < l->ntools; t++) {
    l->tool_stiffness[t] = si->tools._buffer[t].stiffness;
    l->tool_max_force[t] = si->tools._buffer[t].max_force;
    l->tool_reach[t] = si->tools._buffer[t].length + si->tools._buffer[t].radius;
  }
}

int seat_server_scene(seat_server_t *s, dds_entity_t r_scene, const dds_sample_info_t *info,
                      const viscera_SceneInfo *si) {
  if (!info->valid_data) return 0;
  dds_builtintopic_endpoint_t *ep = dds_get_matched_publication_data(r_scene, info->publication_handle);
  pthread_mutex_lock(&s->lock);
  int ok = 0;
  if (ep && claims_server(s, ep)) {
    ok = 1;
    if (!s->known || memcmp(&s->guid, &ep->participant_key, sizeof s->guid) != 0) {
      /* The newest server of the seat (a restart is a new participant). */
      s->known = 1;
      s->guid = ep->participant_key;
      s->generation++;
      s->adopted++;
    }
    s->scene_writer = info->publication_handle;
    limits_from(&s->limits, si);
  } else {
    s->scene_refused++;
  }
  pthread_mutex_unlock(&s->lock);
  if (ep) dds_builtintopic_free_endpoint(ep);
  return ok;
}

seat_verdict_t seat_server_from(seat_server_t *s, dds_entity_t reader, dds_instance_handle_t pub) {
  pthread_mutex_lock(&s->lock);
  for (size_t i = 0; i < s->ncache; i++)
    if (s->cache[i].writer == pub &&
        (s->cache[i].generation == s->generation || s->cache[i].verdict == SEAT_NOT_SERVER)) {
      seat_verdict_t v = s->cache[i].verdict;
      pthread_mutex_unlock(&s->lock);
      return v;
    }
  pthread_mutex_unlock(&s->lock);
  dds_builtintopic_endpoint_t *ep = dds_get_matched_publication_data(reader, pub);
  if (!ep) return SEAT_OTHER_SERVER; /* gone already: not judged, not cached */
  pthread_mutex_lock(&s->lock);
  seat_verdict_t v = SEAT_NOT_SERVER;
  if (s->known && memcmp(&s->guid, &ep->participant_key, sizeof s->guid) == 0)
    v = SEAT_FROM_SERVER;
  else if (claims_server(s, ep))
    v = SEAT_OTHER_SERVER;
  size_t slot = s->ncache;
  if (slot < SEAT_SERVER_CACHE)
    s->ncache++;
  else {
    slot = s->next_recycle;
    s->next_recycle = (s->next_recycle + 1) % SEAT_SERVER_CACHE;
  }
  s->cache[slot].writer = pub;
  s->cache[slot].generation = s->generation;
  s->cache[slot].verdict = v;
  pthread_mutex_unlock(&s->lock);
  dds_builtintopic_free_endpoint(ep);
  return v;
}

int seat_server_limits(seat_server_t *s, seat_limits_t *out) {
  pthread_mutex_lock(&s->lock);
  int k = s->known;
  if (k) *out = s->limits;
  pthread_mutex_unlock(&s->lock);
  return k;
}
