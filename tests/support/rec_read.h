/* SPDX-License-Identifier: Apache-2.0 */
/* rec_read: the strict reading the integration-test tools (rec_tools,
 * rec_topology, rec_palpation) do on a recording: every data sample of a
 * topic decoded with the compiled-in descriptor (rec_decode_topic), and
 * anything short of a complete read (a sample that does not decode, a
 * damaged region or an impossible row) reported on stderr and counted,
 * because the tests read recordings they just made and a salvage there is
 * a failure. */
#ifndef VISCERA_TEST_REC_READ_H
#define VISCERA_TEST_REC_READ_H

#include "recording/rec_decode.h"
#include "recording/recfile.h"

/* Calls `cb` for every decodable data sample of `topic`, in recording
 * order; a topic absent from the recording calls nothing. Returns the
 * number of problems met (0 when the topic was read completely), each
 * reported on stderr prefixed with `tool` and the topic; out of memory
 * counts as one. */
int rec_read_topic(const char *tool, recfile_t *rf, const char *topic, const dds_topic_descriptor_t *desc,
                   rec_decode_cb cb, void *arg);

#endif
