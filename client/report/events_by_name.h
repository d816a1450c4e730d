/* SPDX-License-Identifier: Apache-2.0 */
/* events_by_name: SessionEvents this build's compiled type cannot decode,
 * read through the type recorded with them instead (rec_types.h,
 * rec_cdr.h). A recording made before a field was appended to
 * SessionEvent (task_id, task_name) holds shorter samples the compiled
 * type refuses; their fields are taken by name, the missing ones left at
 * their defaults (task_id -1), so older recordings keep their crossings
 * and tasks in the report. */
#ifndef VISCERA_REPORT_EVENTS_BY_NAME_H
#define VISCERA_REPORT_EVENTS_BY_NAME_H

#include <stdint.h>

#include "recording/rec_decode.h"
#include "recording/recfile.h"

/* Calls cb (as rec_decode_topic would) for every SessionEvent data sample
 * that does not decode with the compiled type but does with the recorded
 * one. Returns how many were delivered; *left counts those neither could
 * read. */
uint64_t rep_events_by_name(recfile_t *rf, rec_decode_cb cb, void *arg, uint64_t *left);

#endif
