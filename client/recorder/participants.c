/* SPDX-License-Identifier: Apache-2.0 */
#include "participants.h"

#include <stdlib.h>
#include <string.h>

#include "dds/vdds_config.h"
#include "dds/vdds_ident.h"
#include "dds/vdds_subject.h"
#include "vtime.h"

struct participants {
  dds_entity_t reader;
  /* GUIDs already stored, to enforce PARTICIPANTS_MAX (linear search is
   * fine: discovery events are rare next to samples). */
  uint8_t (*known)[16];
  size_t nknown;
  uint64_t dropped;
  bool warned;
  /* Subjects are kept only when this recorder authenticates its peers
   * (vdds_subject.h): without security a GUID proves nothing. */
  bool secure;
};

int participants_open(participants_t **out, dds_entity_t participant, verr_t *err) {
  *out = NULL;
  participants_t *p = calloc(1, sizeof *p);
  if (!p) return verr_set(err, "out of memory");
  p->known = calloc(PARTICIPANTS_MAX, sizeof *p->known);
  /* Default reader QoS on a built-in topic is what Cyclone serves from its
   * discovery cache: reliable, transient-local, so participants that were
   * there before the recorder started are reported too. */
  p->reader = p->known ? dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSPARTICIPANT, NULL, NULL) : -1;
  if (p->reader < 0) {
    verr_set(err, "DDS: cannot read DCPSParticipant: %s", p->known ? dds_strretcode(p->reader) : "out of memory");
    free(p->known);
    free(p);
    return -1;
  }
  p->secure = vdds_config_secure() != 0;
  *out = p;
  return 0;
}

static bool known(participants_t *p, const uint8_t g[16], bool add) {
  for (size_t i = 0; i < p->nknown; i++)
    if (memcmp(p->known[i], g, 16) == 0) return true;
  if (!add || p->nknown >= PARTICIPANTS_MAX) return false;
  memcpy(p->known[p->nknown++], g, 16);
  return true;
}

int participants_poll(participants_t *p, store_t *store, FILE *log, verr_t *err) {
  enum { BATCH = 16 };
  for (;;) {
    void *ptrs[BATCH] = {0};
    dds_sample_info_t info[BATCH];
    int n = dds_take(p->reader, ptrs, info, BATCH, BATCH);
    if (n < 0) {
      if (log) fprintf(log, "recorder: DDS: reading DCPSParticipant failed: %s\n", dds_strretcode(n));
      return 0;
    }
    int ret = 0;
    int64_t now = vtime_wall_ns();
    for (int i = 0; i < n && ret == 0; i++) {
      const dds_builtintopic_participant_t *bp = ptrs[i];
      const uint8_t *guid = bp->key.v;
      bool left = info[i].instance_state != DDS_IST_ALIVE;
      if (left) {
        if (known(p, guid, false)) ret = store_note_participant(store, guid, NULL, NULL, true, now, err);
        continue;
      }
      if (!info[i].valid_data) continue;
      if (!known(p, guid, true)) {
        p->dropped++;
        if (!p->warned && log)
          fprintf(log, "recorder: more than %d participants in the domain; further ones are not stored\n",
                  PARTICIPANTS_MAX);
        p->warned = true;
        continue;
      }
      void *ud = NULL;
      size_t udsz = 0;
      char text[VDDS_IDENT_MAX] = "", role[VDDS_ROLE_MAX] = "";
      if (bp->qos && dds_qget_userdata(bp->qos, &ud, &udsz) && ud) vdds_ident_sanitize(text, sizeof text, ud, udsz);
      dds_free(ud);
      bool has_role = vdds_ident_role(text, role, sizeof role) == 0;
      char subject[VDDS_SUBJECT_TEXT_MAX] = "";
      int sv = p->secure ? vdds_subject_verify(text, guid, subject, sizeof subject) : VDDS_SUBJECT_NONE;
      if (sv == VDDS_SUBJECT_MISMATCH && log)
        fprintf(log, "recorder: a participant announced a certificate subject its authenticated GUID does not match;"
                     " not stored\n");
      /* The subject's hex is stored as text once, in its own column. */
      char *c = strstr(text, " cert=");
      if (c) *c = 0;
      ret = store_note_participant(store, guid, text, has_role ? role : NULL, false, now, err);
      if (ret == 0 && sv == VDDS_SUBJECT_VERIFIED) ret = store_note_subject(store, guid, subject, err);
    }
    if (n > 0) dds_return_loan(p->reader, ptrs, n);
    if (ret < 0) return -1;
    if (n < BATCH) return 0;
  }
}

void participants_close(participants_t *p) {
  if (!p) return;
  dds_delete(p->reader);
  free(p->known);
  free(p);
}
