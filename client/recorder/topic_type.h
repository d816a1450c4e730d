/* SPDX-License-Identifier: Apache-2.0 */
/* topic_type: turns a discovered writer's type information into a topic
 * descriptor the recorder can create a topic from, with no compiled-in
 * type.
 *
 * Uses dds_builtintopic_get_endpoint_type_info on the writer's QoS and
 * dds_create_topic_descriptor with DDS_FIND_SCOPE_GLOBAL, which sends a
 * type-lookup request to the writer's node when the type object is not
 * known locally and waits for the reply up to a timeout. */
#ifndef VISCERA_REC_TOPIC_TYPE_H
#define VISCERA_REC_TOPIC_TYPE_H

#include <dds/dds.h>

#include "verr.h"

typedef enum topic_type_result {
  TOPIC_TYPE_OK,    /* *desc set; free with dds_delete_topic_descriptor */
  TOPIC_TYPE_RETRY, /* not resolved within the timeout; worth asking again */
  TOPIC_TYPE_FAIL   /* cannot work for this writer (err says why) */
} topic_type_result_t;

topic_type_result_t topic_type_resolve(dds_entity_t participant, const char *type_name, const dds_qos_t *writer_qos,
                                       dds_duration_t timeout, dds_topic_descriptor_t **desc, verr_t *err);

#endif
