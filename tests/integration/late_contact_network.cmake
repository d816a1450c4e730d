# SPDX-License-Identifier: Apache-2.0
# The late first contact model across an emulated site link (issue 14 item
# 3): palpate_kidney.traj's own linear press, whose first contact sample
# reaches the client after the hand has stopped from about 100 ms one way.
# Label network, skip (77) without root or namespaces; one lock with the
# other network tests.
if(EXISTS ${PROJECT_SOURCE_DIR}/tests/network/sites.sh AND EXISTS ${PROJECT_SOURCE_DIR}/tests/network/prelude.sh)
  add_test(NAME net_late_contact COMMAND bash ${PROJECT_SOURCE_DIR}/tests/network/late_contact_test.sh
                                         ${PROJECT_BINARY_DIR} ${PROJECT_SOURCE_DIR}
                                         ${CMAKE_CURRENT_BINARY_DIR}/net_late_contact.out)
  set_tests_properties(net_late_contact PROPERTIES LABELS network TIMEOUT 120 SKIP_RETURN_CODE 77 RESOURCE_LOCK
                                                   viscera_sites ENVIRONMENT "VISCERA_DOMAIN=181")
endif()
