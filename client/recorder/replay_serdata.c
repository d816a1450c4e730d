/* SPDX-License-Identifier: Apache-2.0 */
#include "replay_serdata.h"

#include <string.h>

#include <dds/ddsi/ddsi_serdata.h>
#include <dds/ddsi/ddsi_sertype.h>
#include <dds/ddsi/q_protocol.h>

typedef struct replay_serdata {
  struct ddsi_serdata c;
  const unsigned char *bytes; /* borrowed: valid for the dds_forwardcdr call */
  uint32_t len;
} replay_serdata_t;

static uint32_t rsd_get_size(const struct ddsi_serdata *d) { return ((const replay_serdata_t *)d)->len; }

static void rsd_to_ser(const struct ddsi_serdata *d, size_t off, size_t sz, void *buf) {
  const replay_serdata_t *s = (const replay_serdata_t *)d;
  if (off >= s->len) return;
  if (sz > s->len - off) sz = s->len - off;
  memcpy(buf, s->bytes + off, sz);
}

static struct ddsi_serdata *rsd_to_ser_ref(const struct ddsi_serdata *d, size_t off, size_t sz, ddsrt_iovec_t *ref) {
  const replay_serdata_t *s = (const replay_serdata_t *)d;
  if (off > s->len) off = s->len;
  if (sz > s->len - off) sz = s->len - off;
  ref->iov_base = (void *)(uintptr_t)(s->bytes + off);
  ref->iov_len = (ddsrt_iov_len_t)sz;
  return ddsi_serdata_ref(d);
}

static void rsd_to_ser_unref(struct ddsi_serdata *d, const ddsrt_iovec_t *ref) {
  (void)ref;
  ddsi_serdata_unref(d);
}

/* Lives on the caller's stack: nothing to free. */
static void rsd_free(struct ddsi_serdata *d) { (void)d; }

static const struct ddsi_serdata_ops rsd_ops = {
    .get_size = rsd_get_size,
    .to_ser = rsd_to_ser,
    .to_ser_ref = rsd_to_ser_ref,
    .to_ser_unref = rsd_to_ser_unref,
    .free = rsd_free,
};

static const struct ddsi_sertype_ops rsd_type_ops = {.version = ddsi_sertype_v0};

dds_return_t replay_serdata_forward(dds_entity_t writer, const void *cdr, size_t len, bool key_only,
                                    replay_serdata_status_t status, dds_time_t source_ts) {
  if (!cdr || len < 4 || len > UINT32_MAX) return DDS_RETCODE_BAD_PARAMETER;
  struct ddsi_sertype type;
  memset(&type, 0, sizeof type);
  type.ops = &rsd_type_ops;
  type.serdata_ops = &rsd_ops;
  replay_serdata_t sd;
  memset(&sd, 0, sizeof sd);
  ddsi_serdata_init(&sd.c, &type, key_only ? SDK_KEY : SDK_DATA);
  sd.bytes = cdr;
  sd.len = (uint32_t)len;
  sd.c.timestamp.v = source_ts;
  sd.c.statusinfo = status == RSD_DISPOSE      ? NN_STATUSINFO_DISPOSE
                    : status == RSD_UNREGISTER ? NN_STATUSINFO_UNREGISTER
                                               : 0;
  /* dds_forwardcdr consumes the one reference; the converted copy it sends
   * is the writer's own serdata, so nothing refers to `sd` afterwards. */
  return dds_forwardcdr(writer, &sd.c);
}
