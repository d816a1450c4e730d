# SPDX-License-Identifier: Apache-2.0
# End-to-end tests of the whole loop: real processes over Cyclone DDS on
# loopback, each on its own domain id.
add_executable(img_diff ${CMAKE_CURRENT_LIST_DIR}/img_diff.c)
target_link_libraries(img_diff PRIVATE PkgConfig::PNG)
add_executable(obj_compare ${CMAKE_CURRENT_LIST_DIR}/obj_compare.c)
target_link_libraries(obj_compare PRIVATE ${MATH_LIB})
add_executable(bad_commands ${CMAKE_CURRENT_LIST_DIR}/bad_commands.c)
target_link_libraries(bad_commands PRIVATE viscera_dds)

set(VISCERA_IT_ENV "CYCLONEDDS_URI=file://${VISCERA_DDS_CONFIG};VISCERA_SHARED_DIR=${VISCERA_SHARED_DIR}")
macro(viscera_integration_test name domain script)
  add_test(NAME ${name} COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/${script} ${PROJECT_BINARY_DIR} ${PROJECT_SOURCE_DIR}
           ${CMAKE_CURRENT_BINARY_DIR}/${name}.out)
  set_tests_properties(${name} PROPERTIES LABELS integration TIMEOUT 180
                       ENVIRONMENT "${VISCERA_IT_ENV};VISCERA_DOMAIN=${domain}")
endmacro()

viscera_integration_test(session_e2e 11 session_test.sh)
viscera_integration_test(late_join 12 late_join_test.sh)
viscera_integration_test(bad_commands 13 bad_commands_test.sh)
viscera_integration_test(bad_input 14 bad_input_test.sh)
viscera_integration_test(failover 15 failover_test.sh)
viscera_integration_test(example_scenes 16 scenes_test.sh)
# deploy/session.sh says which process failed and why (a refused scene, a missing trajectory).
viscera_integration_test(session_failures 199 session_failures_test.sh)
