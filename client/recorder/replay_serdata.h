/* SPDX-License-Identifier: Apache-2.0 */
/* replay_serdata: a minimal serdata that wraps stored CDR bytes (4-byte
 * encapsulation header included) so they can be handed to dds_forwardcdr
 * with their original source timestamp and status info.
 *
 * Its sertype is a stand-in, never registered: dds_forwardcdr sees that it
 * differs from the writer's type and converts through
 * ddsi_serdata_ref_as_type, which needs only the size and the serialised
 * bytes (get_size, to_ser_ref/unref, free); the writer's own type then
 * validates (normalises) the bytes and computes the key. */
#ifndef VISCERA_REC_REPLAY_SERDATA_H
#define VISCERA_REC_REPLAY_SERDATA_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <dds/dds.h>

typedef enum replay_serdata_status { RSD_DATA, RSD_DISPOSE, RSD_UNREGISTER } replay_serdata_status_t;

/* Forwards `len` bytes at `cdr` on `writer`, as a key-only sample when
 * `key_only`. Returns the dds_forwardcdr result. */
dds_return_t replay_serdata_forward(dds_entity_t writer, const void *cdr, size_t len, bool key_only,
                                    replay_serdata_status_t status, dds_time_t source_ts);

#endif
