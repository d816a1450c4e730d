# SPDX-License-Identifier: Apache-2.0
# Topology change cost on the server (model change, tree rebuild and proxy
# re-attachment, keyframe publish); prints a table. DDS on loopback, domain 84.
add_executable(bench_topology ${CMAKE_CURRENT_LIST_DIR}/bench_topology.c)
target_link_libraries(bench_topology PRIVATE viscera_session viscera_test_support)
# A quick run proves the benchmark still works (figures are not checked).
add_test(NAME bench_topology_smoke COMMAND bench_topology ${PROJECT_SOURCE_DIR}/assets --quick)
set_tests_properties(bench_topology_smoke PROPERTIES LABELS bench TIMEOUT 300
                     ENVIRONMENT "CYCLONEDDS_URI=file://${VISCERA_DDS_CONFIG}")
