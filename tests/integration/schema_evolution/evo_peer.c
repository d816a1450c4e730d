/* SPDX-License-Identifier: Apache-2.0 */
/* One side of the schema-evolution test (schema_evolution_test.sh), built
 * once per type version (EVO_VERSION 1: evo_v1.idl, 2: evo_v2.idl, the same
 * type with a member appended to each struct): `write DOMAIN` publishes one
 * sample once a reader matched and its delivery is acknowledged; `read
 * DOMAIN` prints the first sample it takes as key=value words. Real Cyclone
 * DDS between two processes: the writer's and the reader's type differ. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <dds/dds.h>

#if EVO_VERSION == 1
#include "evo_v1.h"
#else
#include "evo_v2.h"
#endif

static dds_qos_t *qos(void) {
  dds_qos_t *q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
  return q;
}

static int wait_status(dds_entity_t e, uint32_t mask, int tenths) {
  for (int i = 0; i < tenths; i++) {
    uint32_t st = 0;
    if (dds_take_status(e, &st, mask) == 0 && st) return 0;
    dds_sleepfor(DDS_MSECS(100));
  }
  return -1;
}

static int do_write(dds_entity_t pp, dds_entity_t tp) {
  dds_qos_t *q = qos();
  dds_entity_t w = dds_create_writer(pp, tp, q, NULL);
  dds_delete_qos(q);
  if (w < 0 || wait_status(w, DDS_PUBLICATION_MATCHED_STATUS, 150) < 0) return fprintf(stderr, "no reader\n"), 1;
  evo_Item items[2] = {{.id = 11, .v = {1.5f, -2.5f}}, {.id = 12, .v = {3.5f, 4.5f}}};
  float samples[3] = {0.25f, 0.5f, 0.75f};
  evo_Reading r = {.sensor = 3, .seq = 77, .items = {2, 2, items, false}, .samples = {3, 3, samples, false}};
  snprintf(r.note, sizeof r.note, "v%d", EVO_VERSION);
#if EVO_VERSION >= 2
  items[0].tag = 7, items[1].tag = 8;
  r.grown = 42.5;
#endif
  if (dds_write(w, &r) != 0 || dds_wait_for_acks(w, DDS_SECS(10)) != 0) return fprintf(stderr, "write failed\n"), 1;
  printf("wrote v%d\n", EVO_VERSION);
  return 0;
}

static int do_read(dds_entity_t pp, dds_entity_t tp) {
  dds_qos_t *q = qos();
  dds_entity_t rd = dds_create_reader(pp, tp, q, NULL);
  dds_delete_qos(q);
  if (rd < 0) return 1;
  printf("ready\n");
  fflush(stdout);
  void *buf[1] = {NULL};
  dds_sample_info_t info;
  for (int i = 0; i < 200; i++) { /* 20 s */
    if (dds_take(rd, buf, &info, 1, 1) == 1 && info.valid_data) {
      const evo_Reading *r = buf[0];
      printf("reader=v%d sensor=%u seq=%llu note=%s items=%u samples=%u", EVO_VERSION, r->sensor,
             (unsigned long long)r->seq, r->note, r->items._length, r->samples._length);
      for (uint32_t k = 0; k < r->items._length; k++)
        printf(" item%u.id=%u item%u.v=%g,%g", k, r->items._buffer[k].id, k, r->items._buffer[k].v[0],
               r->items._buffer[k].v[1]);
      for (uint32_t k = 0; k < r->samples._length; k++) printf(" sample%u=%g", k, r->samples._buffer[k]);
#if EVO_VERSION >= 2
      for (uint32_t k = 0; k < r->items._length; k++) printf(" item%u.tag=%u", k, r->items._buffer[k].tag);
      printf(" grown=%g", r->grown);
#endif
      printf("\n");
      dds_return_loan(rd, buf, 1);
      return 0;
    }
    dds_sleepfor(DDS_MSECS(100));
  }
  fprintf(stderr, "no sample\n");
  return 1;
}

int main(int argc, char **argv) {
  if (argc != 3 || (strcmp(argv[1], "write") && strcmp(argv[1], "read")))
    return fprintf(stderr, "usage: %s write|read DOMAIN\n", argv[0]), 2;
  dds_entity_t pp = dds_create_participant((dds_domainid_t)atoi(argv[2]), NULL, NULL);
  dds_entity_t tp = pp > 0 ? dds_create_topic(pp, &evo_Reading_desc, "evo_reading", NULL, NULL) : -1;
  if (tp < 0) return fprintf(stderr, "no participant or topic\n"), 1;
  int rc = strcmp(argv[1], "write") == 0 ? do_write(pp, tp) : do_read(pp, tp);
  dds_delete(pp);
  return rc;
}
