# SPDX-License-Identifier: Apache-2.0
# Classroom load benchmark (issue 7): deploy/load_bench.sh starts seats and
# light subscribers (delta_sub); the smoke test runs it for a few seconds.
add_executable(delta_sub ${CMAKE_CURRENT_LIST_DIR}/delta_sub.c)
target_link_libraries(delta_sub PRIVATE viscera_dds)
add_test(NAME load_bench_smoke COMMAND bash ${PROJECT_SOURCE_DIR}/deploy/load_bench.sh --build ${PROJECT_BINARY_DIR}
         --out ${CMAKE_CURRENT_BINARY_DIR}/load_smoke --seats 2 --subscribers 4 --duration 12 --baseline 3)
set_tests_properties(load_bench_smoke PROPERTIES LABELS bench TIMEOUT 120
  ENVIRONMENT "CYCLONEDDS_URI=file://${VISCERA_DDS_CONFIG};VISCERA_DOMAIN=148")
