# SPDX-License-Identifier: Apache-2.0
# Remote sessions across emulated sites (issue 14 items 3, 4, 7), haptic
# side. The scripts source the two-site harness tests/network/prelude.sh and
# sites.sh and run link_emu (tests/network/, another branch of issue 14):
# registered only where that harness is in the tree. Label network, skip
# (77) without root or namespaces; one lock with the other network tests.
if(EXISTS ${PROJECT_SOURCE_DIR}/tests/network/sites.sh AND EXISTS ${PROJECT_SOURCE_DIR}/tests/network/prelude.sh)
  foreach(spec "net_haptic_palpation;224;haptic_palpation_test.sh" "net_haptic_guide;225;haptic_guide_test.sh"
               "net_haptic_partition;226;haptic_partition_test.sh")
    list(GET spec 0 name)
    list(GET spec 1 domain)
    list(GET spec 2 script)
    add_test(NAME ${name} COMMAND bash ${PROJECT_SOURCE_DIR}/tests/network/${script} ${PROJECT_BINARY_DIR}
                                  ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_BINARY_DIR}/${name}.out)
    set_tests_properties(${name} PROPERTIES LABELS network TIMEOUT 150 SKIP_RETURN_CODE 77 RESOURCE_LOCK viscera_sites
                                            ENVIRONMENT "VISCERA_DOMAIN=${domain}")
  endforeach()
endif()
