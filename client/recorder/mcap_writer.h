/* SPDX-License-Identifier: Apache-2.0 */
/* mcap_writer: writes an MCAP file (the published MCAP format, major
 * version 0): magic, Header, the data section (Schema and Channel records,
 * then the messages in uncompressed Chunks, each followed by one Message
 * Index per channel), Data End with the CRC-32 of the data section, the
 * summary section (Schemas, Channels, Statistics with per-channel message
 * counts, Chunk Indexes) with its Summary Offsets, and the Footer with the
 * summary CRC. Readers can then stream the file or seek through its index.
 *
 * Schemas and channels must be added before the first message. Ids are
 * the caller's (schema ids from 1; 0 means a channel without schema).
 * Not thread-safe; every function returns 0, or -1 with err naming the
 * file (a failed write stops the writer; later calls fail too). */
#ifndef VISCERA_MCAP_WRITER_H
#define VISCERA_MCAP_WRITER_H

#include <stddef.h>
#include <stdint.h>

#include "verr.h"

typedef struct mcap_writer mcap_writer_t;

/* Messages are gathered into chunks of about this many bytes. */
#define MCAP_CHUNK_BYTES (1024u * 1024u)

int mcap_open(mcap_writer_t **out, const char *path, const char *profile, const char *library, verr_t *err);
int mcap_schema(mcap_writer_t *w, uint16_t id, const char *name, const char *encoding, const void *data, size_t len,
                verr_t *err);
/* meta: nmeta key/value pairs (meta[2k], meta[2k+1]). */
int mcap_channel(mcap_writer_t *w, uint16_t id, uint16_t schema_id, const char *topic, const char *encoding,
                 const char *const *meta, size_t nmeta, verr_t *err);
int mcap_message(mcap_writer_t *w, uint16_t channel, uint32_t sequence, uint64_t log_time, uint64_t publish_time,
                 const void *data, size_t len, verr_t *err);
/* Writes the last chunk, the summary and the footer, closes and frees w
 * (even on failure). */
int mcap_close(mcap_writer_t *w, verr_t *err);

/* CRC-32 (IEEE 802.3, as MCAP uses), continuing from `crc` (0 to start). */
uint32_t mcap_crc32(uint32_t crc, const void *data, size_t len);

#endif
