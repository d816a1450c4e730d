/* SPDX-License-Identifier: Apache-2.0 */
#include "mcap_writer.h"

#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Record opcodes of the MCAP format. */
enum {
  OP_HEADER = 0x01,
  OP_FOOTER = 0x02,
  OP_SCHEMA = 0x03,
  OP_CHANNEL = 0x04,
  OP_MESSAGE = 0x05,
  OP_CHUNK = 0x06,
  OP_MESSAGE_INDEX = 0x07,
  OP_CHUNK_INDEX = 0x08,
  OP_STATISTICS = 0x0B,
  OP_SUMMARY_OFFSET = 0x0E,
  OP_DATA_END = 0x0F
};

static const uint8_t MAGIC[8] = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};

uint32_t mcap_crc32(uint32_t crc, const void *data, size_t len) {
  static uint32_t table[256];
  static bool ready; /* idempotent fill, same values from any thread */
  if (!ready) {
    for (uint32_t i = 0; i < 256; i++) {
      uint32_t c = i;
      for (int k = 0; k < 8; k++) c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      table[i] = c;
    }
    ready = true;
  }
  const uint8_t *p = data;
  crc = ~crc;
  for (size_t i = 0; i < len; i++) crc = table[(crc ^ p[i]) & 0xff] ^ (crc >> 8);
  return ~crc;
}

/* A little-endian byte buffer. */
typedef struct bb {
  uint8_t *p;
  size_t n, cap;
  bool oom;
} bb_t;

static void put(bb_t *b, const void *d, size_t len) {
  if (b->oom) return;
  if (b->n + len > b->cap) {
    size_t nc = b->cap ? b->cap : 4096;
    while (nc < b->n + len) nc *= 2;
    uint8_t *np = realloc(b->p, nc);
    if (!np) {
      b->oom = true;
      return;
    }
    b->p = np, b->cap = nc;
  }
  if (len) memcpy(b->p + b->n, d, len);
  b->n += len;
}
static void put_uint(bb_t *b, uint64_t v, int bytes) {
  uint8_t x[8];
  for (int i = 0; i < bytes; i++) x[i] = (uint8_t)(v >> (8 * i));
  put(b, x, (size_t)bytes);
}
static void put_u8(bb_t *b, uint8_t v) { put_uint(b, v, 1); }
static void put_u16(bb_t *b, uint16_t v) { put_uint(b, v, 2); }
static void put_u32(bb_t *b, uint32_t v) { put_uint(b, v, 4); }
static void put_u64(bb_t *b, uint64_t v) { put_uint(b, v, 8); }
static void put_str(bb_t *b, const char *s) {
  size_t len = strlen(s);
  put_u32(b, (uint32_t)len);
  put(b, s, len);
}
/* A record: opcode, content length, content. */
static void put_record(bb_t *b, uint8_t op, const bb_t *content) {
  put_u8(b, op);
  put_u64(b, content->n);
  put(b, content->p, content->n);
}

typedef struct index_entry {
  uint64_t time, offset;
} index_entry_t;

typedef struct channel {
  bool used;
  uint64_t messages;
  index_entry_t *idx; /* this chunk's messages */
  size_t nidx, capidx;
} channel_t;

struct mcap_writer {
  FILE *f;
  char path[512];
  uint64_t pos;
  uint32_t data_crc, summary_crc;
  bool in_summary, failed;
  verr_t fail_err;
  bb_t schemas, channels; /* their records, written again in the summary */
  uint16_t nschemas;
  uint32_t nchannels;
  channel_t *chan; /* by channel id, 65536 */
  bb_t chunk;      /* the open chunk's records */
  uint64_t chunk_start_time, chunk_end_time;
  bb_t chunk_indexes;
  uint32_t nchunks;
  uint64_t messages, start_time, end_time;
};

static int out(mcap_writer_t *w, const void *d, size_t len, verr_t *err) {
  if (w->failed) {
    if (err) *err = w->fail_err;
    return -1;
  }
  if (len && fwrite(d, 1, len, w->f) != len) {
    w->failed = true;
    verr_set(&w->fail_err, "%s: write failed: %s", w->path, strerror(errno));
    if (err) *err = w->fail_err;
    return -1;
  }
  w->pos += len;
  if (w->in_summary)
    w->summary_crc = mcap_crc32(w->summary_crc, d, len);
  else
    w->data_crc = mcap_crc32(w->data_crc, d, len);
  return 0;
}

static int out_bb(mcap_writer_t *w, bb_t *b, verr_t *err) {
  if (b->oom) return verr_set(err, "%s: out of memory", w->path);
  int r = out(w, b->p, b->n, err);
  b->n = 0;
  return r;
}

int mcap_open(mcap_writer_t **outw, const char *path, const char *profile, const char *library, verr_t *err) {
  *outw = NULL;
  mcap_writer_t *w = calloc(1, sizeof *w);
  if (!w) return verr_set(err, "%s: out of memory", path);
  w->chan = calloc(65536, sizeof *w->chan);
  snprintf(w->path, sizeof w->path, "%s", path);
  w->f = w->chan ? fopen(path, "wb") : NULL;
  if (!w->f) {
    verr_set(err, "%s: cannot create: %s", path, w->chan ? strerror(errno) : "out of memory");
    free(w->chan);
    free(w);
    return -1;
  }
  w->start_time = UINT64_MAX;
  bb_t h = {0}, rec = {0};
  put_str(&h, profile);
  put_str(&h, library);
  put_record(&rec, OP_HEADER, &h);
  free(h.p);
  *outw = w;
  int r = out(w, MAGIC, sizeof MAGIC, err);
  if (r == 0) r = out_bb(w, &rec, err);
  free(rec.p);
  return r;
}

int mcap_schema(mcap_writer_t *w, uint16_t id, const char *name, const char *encoding, const void *data, size_t len,
                verr_t *err) {
  if (!id || len > UINT32_MAX) return verr_set(err, "%s: schema '%s': id 0 or too large", w->path, name);
  bb_t c = {0}, rec = {0};
  put_u16(&c, id);
  put_str(&c, name);
  put_str(&c, encoding);
  put_u32(&c, (uint32_t)len);
  put(&c, data, len);
  put_record(&rec, OP_SCHEMA, &c);
  put(&w->schemas, rec.p, rec.n);
  w->nschemas++;
  free(c.p);
  int r = out_bb(w, &rec, err);
  free(rec.p);
  return r;
}

int mcap_channel(mcap_writer_t *w, uint16_t id, uint16_t schema_id, const char *topic, const char *encoding,
                 const char *const *meta, size_t nmeta, verr_t *err) {
  bb_t c = {0}, m = {0}, rec = {0};
  put_u16(&c, id);
  put_u16(&c, schema_id);
  put_str(&c, topic);
  put_str(&c, encoding);
  for (size_t i = 0; i < nmeta; i++) {
    put_str(&m, meta[2 * i]);
    put_str(&m, meta[2 * i + 1]);
  }
  put_u32(&c, (uint32_t)m.n);
  put(&c, m.p, m.n);
  put_record(&rec, OP_CHANNEL, &c);
  put(&w->channels, rec.p, rec.n);
  w->nchannels++;
  w->chan[id].used = true;
  free(c.p);
  free(m.p);
  int r = out_bb(w, &rec, err);
  free(rec.p);
  return r;
}

/* Writes the open chunk, then its message indexes, and keeps its index. */
static int flush_chunk(mcap_writer_t *w, verr_t *err) {
  if (!w->chunk.n) return 0;
  if (w->chunk.oom) return verr_set(err, "%s: out of memory", w->path);
  uint64_t start = w->pos;
  bb_t c = {0}, rec = {0};
  put_u64(&c, w->chunk_start_time);
  put_u64(&c, w->chunk_end_time);
  put_u64(&c, w->chunk.n);
  put_u32(&c, mcap_crc32(0, w->chunk.p, w->chunk.n));
  put_str(&c, ""); /* not compressed */
  put_u64(&c, w->chunk.n);
  put(&c, w->chunk.p, w->chunk.n);
  put_record(&rec, OP_CHUNK, &c);
  free(c.p);
  int r = out_bb(w, &rec, err);
  uint64_t chunk_len = w->pos - start;
  bb_t offsets = {0};
  for (uint32_t id = 0; id < 65536 && r == 0; id++) {
    channel_t *ch = &w->chan[id];
    if (!ch->nidx) continue;
    put_u16(&offsets, (uint16_t)id);
    put_u64(&offsets, w->pos);
    bb_t mi = {0};
    put_u16(&mi, (uint16_t)id);
    put_u32(&mi, (uint32_t)(ch->nidx * 16));
    for (size_t k = 0; k < ch->nidx; k++) {
      put_u64(&mi, ch->idx[k].time);
      put_u64(&mi, ch->idx[k].offset);
    }
    put_record(&rec, OP_MESSAGE_INDEX, &mi);
    free(mi.p);
    r = out_bb(w, &rec, err);
    ch->nidx = 0;
  }
  free(rec.p);
  if (r == 0) {
    bb_t ci = {0};
    put_u64(&ci, w->chunk_start_time);
    put_u64(&ci, w->chunk_end_time);
    put_u64(&ci, start);
    put_u64(&ci, chunk_len);
    put_u32(&ci, (uint32_t)offsets.n);
    put(&ci, offsets.p, offsets.n);
    put_u64(&ci, w->pos - start - chunk_len);
    put_str(&ci, "");
    put_u64(&ci, w->chunk.n);
    put_u64(&ci, w->chunk.n);
    put_record(&w->chunk_indexes, OP_CHUNK_INDEX, &ci);
    free(ci.p);
    w->nchunks++;
  }
  free(offsets.p);
  w->chunk.n = 0;
  return r;
}

int mcap_message(mcap_writer_t *w, uint16_t channel, uint32_t sequence, uint64_t log_time, uint64_t publish_time,
                 const void *data, size_t len, verr_t *err) {
  channel_t *ch = &w->chan[channel];
  if (!ch->used) return verr_set(err, "%s: message on channel %u, which was not added", w->path, channel);
  if (ch->nidx == ch->capidx) {
    size_t nc = ch->capidx ? 2 * ch->capidx : 256;
    index_entry_t *ni = realloc(ch->idx, nc * sizeof *ni);
    if (!ni) return verr_set(err, "%s: out of memory", w->path);
    ch->idx = ni, ch->capidx = nc;
  }
  if (!w->chunk.n) w->chunk_start_time = UINT64_MAX, w->chunk_end_time = 0;
  ch->idx[ch->nidx++] = (index_entry_t){log_time, w->chunk.n};
  put_u8(&w->chunk, OP_MESSAGE);
  put_u64(&w->chunk, 2 + 4 + 8 + 8 + len);
  put_u16(&w->chunk, channel);
  put_u32(&w->chunk, sequence);
  put_u64(&w->chunk, log_time);
  put_u64(&w->chunk, publish_time);
  put(&w->chunk, data, len);
  if (log_time < w->chunk_start_time) w->chunk_start_time = log_time;
  if (log_time > w->chunk_end_time) w->chunk_end_time = log_time;
  if (log_time < w->start_time) w->start_time = log_time;
  if (log_time > w->end_time) w->end_time = log_time;
  w->messages++;
  ch->messages++;
  if (w->chunk.oom) return verr_set(err, "%s: out of memory", w->path);
  return w->chunk.n >= MCAP_CHUNK_BYTES ? flush_chunk(w, err) : 0;
}

/* A group of summary records, and its Summary Offset. */
static int summary_group(mcap_writer_t *w, uint8_t op, bb_t *records, bb_t *offsets, verr_t *err) {
  if (!records->n) return 0;
  put_u8(offsets, OP_SUMMARY_OFFSET);
  put_u64(offsets, 1 + 8 + 8);
  put_u8(offsets, op);
  put_u64(offsets, w->pos);
  put_u64(offsets, records->n);
  return out_bb(w, records, err);
}

static int finish(mcap_writer_t *w, verr_t *err) {
  if (flush_chunk(w, err) < 0) return -1;
  bb_t rec = {0}, c = {0}, offsets = {0}, stats = {0};
  put_u32(&c, w->data_crc);
  put_record(&rec, OP_DATA_END, &c);
  int r = out_bb(w, &rec, err);
  uint64_t summary_start = w->pos;
  w->in_summary = true;
  /* Statistics */
  c.n = 0;
  put_u64(&c, w->messages);
  put_u16(&c, w->nschemas);
  put_u32(&c, w->nchannels);
  put_u32(&c, 0); /* attachments */
  put_u32(&c, 0); /* metadata */
  put_u32(&c, w->nchunks);
  put_u64(&c, w->messages ? w->start_time : 0);
  put_u64(&c, w->messages ? w->end_time : 0);
  bb_t counts = {0};
  for (uint32_t id = 0; id < 65536; id++)
    if (w->chan[id].used) {
      put_u16(&counts, (uint16_t)id);
      put_u64(&counts, w->chan[id].messages);
    }
  put_u32(&c, (uint32_t)counts.n);
  put(&c, counts.p, counts.n);
  put_record(&stats, OP_STATISTICS, &c);
  if (r == 0) r = summary_group(w, OP_SCHEMA, &w->schemas, &offsets, err);
  if (r == 0) r = summary_group(w, OP_CHANNEL, &w->channels, &offsets, err);
  if (r == 0) r = summary_group(w, OP_STATISTICS, &stats, &offsets, err);
  if (r == 0) r = summary_group(w, OP_CHUNK_INDEX, &w->chunk_indexes, &offsets, err);
  uint64_t offset_start = w->pos;
  if (r == 0) r = out_bb(w, &offsets, err);
  /* Footer: the summary CRC runs from the summary start through the
   * footer's summary_offset_start field. */
  c.n = 0;
  put_u8(&c, OP_FOOTER);
  put_u64(&c, 8 + 8 + 4);
  put_u64(&c, summary_start);
  put_u64(&c, offset_start);
  if (r == 0) r = out_bb(w, &c, err);
  put_u32(&c, w->summary_crc);
  if (r == 0) r = out_bb(w, &c, err);
  if (r == 0) r = out(w, MAGIC, sizeof MAGIC, err);
  free(rec.p);
  free(c.p);
  free(offsets.p);
  free(stats.p);
  free(counts.p);
  return r;
}

int mcap_close(mcap_writer_t *w, verr_t *err) {
  if (!w) return 0;
  int r = finish(w, err);
  if (fclose(w->f) != 0 && r == 0) r = verr_set(err, "%s: write failed: %s", w->path, strerror(errno));
  for (uint32_t id = 0; id < 65536; id++) free(w->chan[id].idx);
  free(w->chan);
  free(w->schemas.p);
  free(w->channels.p);
  free(w->chunk.p);
  free(w->chunk_indexes.p);
  free(w);
  return r;
}
