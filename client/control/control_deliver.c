/* SPDX-License-Identifier: Apache-2.0 */
#include "control_deliver.h"

#include <fnmatch.h>
#include <stdio.h>
#include <string.h>

#include "vtime.h"

int control_deliver_open(control_deliver_t *d, dds_entity_t participant, dds_entity_t writer, const char *partition) {
  memset(d, 0, sizeof *d);
  d->participant = participant;
  d->writer = writer;
  snprintf(d->partition, sizeof d->partition, "%s", partition);
  d->r_subs = dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, NULL, NULL);
  return d->r_subs < 0 ? (int)d->r_subs : 0;
}

static int matched(const control_deliver_t *d) {
  dds_publication_matched_status_t st;
  return dds_get_publication_matched_status(d->writer, &st) == DDS_RETCODE_OK ? (int)st.current_count : 0;
}

void control_deliver_wrote(control_deliver_t *d) { d->matched_at_write = matched(d); }

/* 1 when one of the reader's partitions (DDS wildcards allowed) takes ours. */
static int takes_partition(const dds_qos_t *q, const char *ours) {
  uint32_t n = 0;
  char **ps = NULL;
  if (!q || !dds_qget_partition(q, &n, &ps) || n == 0) {
    dds_free(ps);
    return ours[0] == 0;
  }
  int yes = 0;
  for (uint32_t i = 0; i < n; i++) {
    if (!yes && (strcmp(ps[i], ours) == 0 || fnmatch(ps[i], ours, 0) == 0)) yes = 1;
    dds_free(ps[i]);
  }
  dds_free(ps);
  return yes;
}

/* SessionControl readers of other participants in this partition, alive. */
static int known_readers(const control_deliver_t *d) {
  dds_guid_t self;
  if (dds_get_guid(d->participant, &self) != DDS_RETCODE_OK) return 0;
  enum { MAX = 64 }; /* a seat's readers: its server, a recorder or two */
  void *buf[MAX] = {0};
  dds_sample_info_t info[MAX];
  /* read, not take: the set is read again on every pass */
  int k = dds_read_mask(d->r_subs, buf, info, MAX, MAX,
                        DDS_ANY_SAMPLE_STATE | DDS_ANY_VIEW_STATE | DDS_ALIVE_INSTANCE_STATE);
  int n = 0;
  for (int i = 0; i < k; i++) {
    const dds_builtintopic_endpoint_t *ep = buf[i];
    if (!info[i].valid_data || strcmp(ep->topic_name, "viscera_SessionControl") != 0) continue;
    if (memcmp(ep->participant_key.v, self.v, 12) == 0) continue; /* this participant's own */
    if (takes_partition(ep->qos, d->partition)) n++;
  }
  if (k > 0) dds_return_loan(d->r_subs, buf, k);
  return n;
}

int control_deliver_finish(control_deliver_t *d, const void *sample, double min_s, double max_s, int *missing) {
  uint64_t start = vtime_mono_ns();
  *missing = 0;
  for (;;) {
    double t = (double)(vtime_mono_ns() - start) * 1e-9;
    int m = matched(d), known = known_readers(d);
    if (m > d->matched_at_write) { /* matched after the last write: it has not got the command */
      if (dds_write(d->writer, sample) < 0) return 1;
      control_deliver_wrote(d);
    }
    if (t >= min_s && m >= known && dds_wait_for_acks(d->writer, DDS_MSECS(20)) == DDS_RETCODE_OK) return 0;
    if (t >= max_s) {
      *missing = known > m ? known - m : 1;
      return 1;
    }
    dds_sleepfor(DDS_MSECS(20));
  }
}

void control_deliver_close(control_deliver_t *d) {
  if (d->r_subs > 0) dds_delete(d->r_subs);
  d->r_subs = 0;
}
