/* SPDX-License-Identifier: Apache-2.0 */
/* test_dds: values the DDS-side unit tests feed their code without a
 * participant. Header-only (the rest of the support library is DDS-free). */
#ifndef VISCERA_TEST_DDS_H
#define VISCERA_TEST_DDS_H

#include <dds/dds.h>

/* A liveliness-changed status as Cyclone's listener delivers it. */
static inline dds_liveliness_changed_status_t test_liveliness_status(uint32_t alive, uint32_t not_alive, int32_t dalive,
                                                                     int32_t dnot, dds_instance_handle_t h) {
  dds_liveliness_changed_status_t s = {alive, not_alive, dalive, dnot, h};
  return s;
}

#endif
