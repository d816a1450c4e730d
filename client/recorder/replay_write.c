/* SPDX-License-Identifier: Apache-2.0 */
#include "replay_write.h"

#include <stdlib.h>
#include <string.h>

#include <dds/ddsi/ddsi_cdrstream.h>

#include "recording/recording.h"
#include "replay_serdata.h"

bool rp_topic_write(rp_topic_t *t, const recfile_row_t *row, rp_buf_t *b) {
  if (row->cdr_len < 4 || row->cdr_len > UINT32_MAX) return false;
  const unsigned char *hdr = row->cdr;
  /* Encapsulation identifier: CDR_BE/LE 0,1; PL_CDR 2,3: XCDR1; CDR2 6,7,
   * D_CDR2 8,9, PL_CDR2 10,11: XCDR2. The low bit says little-endian. */
  if (hdr[0] != 0 || hdr[1] > 11 || hdr[1] == 4 || hdr[1] == 5) return false;
  uint32_t xcdrv = hdr[1] >= 6 ? 2u : 1u;
  bool little = (hdr[1] & 1) != 0;
  uint32_t size = (uint32_t)row->cdr_len - 4;
  if (b->cap < row->cdr_len) {
    size_t cap = row->cdr_len + 64;
    unsigned char *p = realloc(b->p, cap);
    if (!p) return false;
    b->p = p;
    b->cap = cap;
  }
  memcpy(b->p, (const unsigned char *)row->cdr + 4, size);
  bool just_key = row->kind != REC_KIND_DATA && !row->inferred;
  uint32_t actual = 0;
#if __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  bool bswap = !little;
#else
  bool bswap = little;
#endif
  if (!dds_stream_normalize(b->p, size, bswap, xcdrv, &t->st, just_key, &actual)) return false;
  dds_time_t ts = row->source_ts_ns > 0 ? row->source_ts_ns : dds_time();
  if (!row->inferred) {
    /* The stored bytes themselves, with their timestamp and status. */
    replay_serdata_status_t status = row->kind == REC_KIND_DATA      ? RSD_DATA
                                     : row->kind == REC_KIND_DISPOSE ? RSD_DISPOSE
                                                                     : RSD_UNREGISTER;
    return replay_serdata_forward(t->writer, row->cdr, row->cdr_len, just_key, status, ts) == DDS_RETCODE_OK;
  }
  /* Inferred end of an instance: the row holds a full sample, but a dispose
   * or unregister goes out key-only; decode and let the writer do that. */
  void *sample = calloc(1, t->st.type.size);
  if (!sample) return false;
  dds_istream_t is;
  dds_istream_init(&is, actual, b->p, xcdrv);
  if (just_key)
    dds_stream_read_key(&is, sample, &t->st);
  else
    dds_stream_read_sample(&is, sample, &t->st);
  dds_istream_fini(&is);
  dds_return_t rc;
  switch (row->kind) {
  case REC_KIND_DATA:
    rc = dds_write_ts(t->writer, sample, ts);
    break;
  case REC_KIND_DISPOSE:
    rc = dds_dispose_ts(t->writer, sample, ts);
    break;
  default:
    rc = dds_unregister_instance_ts(t->writer, sample, ts);
    break;
  }
  dds_stream_free_sample(sample, t->ops);
  free(sample);
  return rc == DDS_RETCODE_OK;
}
