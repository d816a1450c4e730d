/* SPDX-License-Identifier: Apache-2.0 */
#include "topic_type.h"

#include <string.h>

topic_type_result_t topic_type_resolve(dds_entity_t participant, const char *type_name, const dds_qos_t *writer_qos,
                                       dds_duration_t timeout, dds_topic_descriptor_t **desc, verr_t *err) {
  *desc = NULL;
  /* The API reads the type information from the endpoint's QoS; a stack
   * endpoint around the kept copy of that QoS avoids holding on to the
   * DCPSPublication loan while the type is resolved. */
  dds_builtintopic_endpoint_t ep;
  memset(&ep, 0, sizeof ep);
  ep.qos = (dds_qos_t *)writer_qos;
  const dds_typeinfo_t *ti = NULL;
  dds_return_t rc = dds_builtintopic_get_endpoint_type_info(&ep, &ti);
  if (rc != DDS_RETCODE_OK || ti == NULL) {
    verr_set(err, "writer sent no XTypes type information for '%s' (not a Cyclone/XTypes writer?)", type_name);
    return TOPIC_TYPE_FAIL;
  }
  rc = dds_create_topic_descriptor(DDS_FIND_SCOPE_GLOBAL, participant, ti, timeout, desc);
  if (rc == DDS_RETCODE_TIMEOUT) {
    verr_set(err, "type '%s' not resolved yet (type lookup timed out)", type_name);
    return TOPIC_TYPE_RETRY;
  }
  if (rc == DDS_RETCODE_UNSUPPORTED) {
    /* Cyclone 0.10's type builder refuses some valid types, notably a
     * bounded string (string<N>) as a @key member; say so, since the
     * fix is in the IDL (unbounded string key, integer key, or no key). */
    verr_set(err,
             "Cyclone cannot rebuild type '%s' from its type information (unsupported construct; in 0.10.x "
             "e.g. a bounded string<N> @key member)",
             type_name);
    return TOPIC_TYPE_FAIL;
  }
  if (rc != DDS_RETCODE_OK) {
    verr_set(err, "cannot build a descriptor for type '%s': %s", type_name, dds_strretcode(rc));
    *desc = NULL;
    return rc == DDS_RETCODE_PRECONDITION_NOT_MET ? TOPIC_TYPE_RETRY : TOPIC_TYPE_FAIL;
  }
  if (strcmp((*desc)->m_typename, type_name) != 0) {
    verr_set(err, "resolved type is '%s', writer announced '%s'", (*desc)->m_typename, type_name);
    dds_delete_topic_descriptor(*desc);
    *desc = NULL;
    return TOPIC_TYPE_FAIL;
  }
  return TOPIC_TYPE_OK;
}
