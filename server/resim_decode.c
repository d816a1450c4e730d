#include "resim_decode.h"

#include <stdlib.h>
#include <string.h>

#include <dds/ddsi/ddsi_cdrstream.h>

bool resim_decode(const void *cdr, size_t len, const dds_topic_descriptor_t *desc, void *out) {
  memset(out, 0, desc->m_size);
  const unsigned char *p = cdr;
  /* Encoding identifiers 0..3 are XCDR1 (plain and parameter list, BE/LE),
   * higher ones XCDR2; the low bit is little-endian. */
  if (!p || len < 4 || len > UINT32_MAX || p[0] != 0) return false;
  unsigned id = p[1];
  bool le = (id & 1u) != 0;
  uint32_t xcdrv = id <= 3 ? 1 : 2;
  uint32_t size = (uint32_t)(len - 4);
  /* The normalizer works in place (byte swapping): on a copy, never on the
   * caller's (SQLite's) buffer. */
  void *buf = malloc(size ? size : 1);
  if (!buf) return false;
  memcpy(buf, p + 4, size);
  uint32_t off = 0;
  bool bswap = le != (DDSRT_ENDIAN == DDSRT_LITTLE_ENDIAN);
  bool ok = dds_stream_normalize_data(buf, &off, size, bswap, xcdrv, desc->m_ops) != NULL;
  if (ok) {
    dds_istream_t is;
    dds_istream_init(&is, size, buf, xcdrv);
    dds_stream_read(&is, out, desc->m_ops);
    dds_istream_fini(&is);
  }
  free(buf);
  return ok;
}

void resim_decode_free(void *sample, const dds_topic_descriptor_t *desc) {
  dds_stream_free_sample(sample, desc->m_ops);
}
