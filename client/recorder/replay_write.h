/* SPDX-License-Identifier: Apache-2.0 */
/* replay_write: one stored sample out again, as it was recorded.
 *
 * The stored CDR is first checked with dds_stream_normalize against the
 * topic's rebuilt type program (replay_topic.h; on a copy: a sample that
 * fails is never handed to DDS). Data rows and explicit dispose/unregister
 * rows (key-only CDR) are then wrapped, bytes unchanged, in a small custom
 * serdata (replay_serdata.h) carrying the ORIGINAL source timestamp and
 * status info, and sent with dds_forwardcdr: Cyclone converts it to the
 * writer's type (which computes key and instance) and keeps timestamp and
 * status. Dispose/unregister rows the recorder inferred from instance
 * state hold a full sample; those are decoded (dds_stream_read_sample) and
 * sent with dds_dispose_ts / dds_unregister_instance_ts, again with the
 * original timestamp. */
#ifndef VISCERA_REPLAY_WRITE_H
#define VISCERA_REPLAY_WRITE_H

#include <stdbool.h>
#include <stddef.h>

#include "recording/recfile.h"
#include "replay_topic.h"

/* The scratch copy the check works on, grown as needed (free p at the end). */
typedef struct rp_buf {
  unsigned char *p;
  size_t cap;
} rp_buf_t;

/* Checks the stored bytes of `row` against t's type and writes them with
 * their source timestamp. Returns true when written, false when the bytes
 * do not fit the type (or out of memory, or DDS refused them). */
bool rp_topic_write(rp_topic_t *t, const recfile_row_t *row, rp_buf_t *b);

#endif
