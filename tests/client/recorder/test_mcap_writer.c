/* SPDX-License-Identifier: Apache-2.0 */
/* mcap_writer: the CRC-32 against its check value, and a file written
 * with two channels and messages spread over several chunks, walked back
 * record by record as the MCAP format lays it out: magic at both ends,
 * the footer's offsets, the data-section and summary CRCs, every chunk's
 * CRC, its messages and the message indexes after it, the statistics.
 * (The integration test recinfo_mcap reads a real export with the MCAP
 * reference reader.) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "mcap_writer.h"

static uint64_t u64(const uint8_t *p) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; i--) v = v << 8 | p[i];
  return v;
}
static uint32_t u32(const uint8_t *p) { return (uint32_t)u64((const uint8_t[8]){p[0], p[1], p[2], p[3]}); }
static uint16_t u16(const uint8_t *p) { return (uint16_t)(p[0] | p[1] << 8); }

int main(void) {
  CHECK(mcap_crc32(0, "123456789", 9) == 0xCBF43926u);
  CHECK(mcap_crc32(mcap_crc32(0, "1234", 4), "56789", 5) == 0xCBF43926u);

  char path[] = "/tmp/test_mcap_XXXXXX";
  int fd = mkstemp(path);
  CHECK(fd >= 0);
  close(fd);
  mcap_writer_t *w = NULL;
  verr_t err = {{0}};
  CHECK(mcap_open(&w, path, "", "test", &err) == 0);
  const char idl[] = "module m { struct A { long x; }; };";
  CHECK(mcap_schema(w, 1, "m::A", "omgidl", idl, sizeof idl - 1, &err) == 0);
  const char *meta[] = {"dds_topic", "a"};
  CHECK(mcap_channel(w, 1, 1, "a", "cdr", meta, 1, &err) == 0);
  CHECK(mcap_channel(w, 2, 1, "b", "cdr", NULL, 0, &err) == 0);
  CHECK(mcap_message(w, 9, 0, 1, 1, "x", 1, &err) < 0); /* no such channel */
  size_t big = 700 * 1024;
  uint8_t *blob = calloc(1, big);
  for (int i = 0; i < 5; i++) { /* two per chunk: three chunks */
    blob[0] = (uint8_t)i;
    CHECK(mcap_message(w, (uint16_t)(1 + i % 2), (uint32_t)i, 1000 + (uint64_t)i, 1000 + (uint64_t)i, blob, big,
                       &err) == 0);
  }
  CHECK(mcap_message(w, 1, 5, 999, 999, "tiny", 4, &err) == 0);
  CHECK(mcap_close(w, &err) == 0);
  free(blob);

  FILE *f = fopen(path, "rb");
  fseek(f, 0, SEEK_END);
  size_t n = (size_t)ftell(f);
  fseek(f, 0, SEEK_SET);
  uint8_t *b = malloc(n);
  CHECK(fread(b, 1, n, f) == n);
  fclose(f);
  unlink(path);
  static const uint8_t MAGIC[8] = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};
  CHECK(memcmp(b, MAGIC, 8) == 0 && memcmp(b + n - 8, MAGIC, 8) == 0);
  const uint8_t *foot = b + n - 8 - 29; /* opcode, length 20, three fields */
  CHECK(foot[0] == 0x02 && u64(foot + 1) == 20);
  uint64_t summary = u64(foot + 9), offsets = u64(foot + 17);
  CHECK(summary < offsets && offsets < n);
  CHECK(u32(foot + 25) == mcap_crc32(0, b + summary, (size_t)(foot + 25 - (b + summary))));
  const uint8_t *dend = b + summary - 13;
  CHECK(dend[0] == 0x0F && u64(dend + 1) == 4 && u32(dend + 9) == mcap_crc32(0, b, (size_t)(dend - b)));

  /* the data section, record by record */
  size_t pos = 8, chunks = 0, messages = 0, indexes = 0;
  int order_ok = 1;
  uint8_t last_op = 0;
  while (pos < (size_t)(dend - b)) {
    uint8_t op = b[pos];
    uint64_t len = u64(b + pos + 1);
    const uint8_t *c = b + pos + 9;
    if (op == 0x06) {
      uint64_t usize = u64(c + 16), rlen = u64(c + 32);
      const uint8_t *recs = c + 40;
      CHECK(u32(c + 24) == mcap_crc32(0, recs, rlen) && usize == rlen && u32(c + 28) == 0 /* "" */);
      for (uint64_t p = 0; p < rlen; p += 9 + u64(recs + p + 1)) {
        CHECK(recs[p] == 0x05);
        messages++;
      }
      chunks++;
    } else if (op == 0x07) {
      indexes++;
      if (last_op != 0x06 && last_op != 0x07) order_ok = 0; /* indexes follow their chunk */
    }
    last_op = op;
    pos += 9 + len;
  }
  CHECK(pos == (size_t)(dend - b));
  CHECK(chunks == 3 && messages == 6 && order_ok);
  CHECK(indexes == 2 + 2 + 1); /* one per channel in each chunk: a+b, a+b, a */
  /* statistics: found through the summary offsets */
  int stats_seen = 0;
  for (size_t p = offsets; p < (size_t)(foot - b); p += 9 + u64(b + p + 1)) {
    CHECK(b[p] == 0x0E);
    if (b[p + 9] != 0x0B) continue;
    const uint8_t *s = b + u64(b + p + 10) + 9;
    CHECK(u64(s) == 6 && u16(s + 8) == 1 && u32(s + 10) == 2 && u32(s + 22) == 3);
    CHECK(u64(s + 26) == 999 && u64(s + 34) == 1004);
    stats_seen = 1;
  }
  CHECK(stats_seen);
  free(b);
  return check_report("test_mcap_writer");
}
