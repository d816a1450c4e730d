# SPDX-License-Identifier: Apache-2.0
# bench_ms_forces: ns per spring of the mass-spring force and Jacobian loops,
# old (one spring at a time, kept in the benchmark) vs new (runs of equal i).
add_executable(bench_ms_forces ${CMAKE_CURRENT_LIST_DIR}/bench_ms_forces.c)
target_link_libraries(bench_ms_forces PRIVATE viscera_test_support)
target_link_libraries(bench_ms_forces PRIVATE viscera_sim)
# A quick run proves the benchmark still works (figures are not checked).
add_test(NAME bench_ms_forces_smoke COMMAND bench_ms_forces --quick)
set_tests_properties(bench_ms_forces_smoke PROPERTIES LABELS bench TIMEOUT 120
  ENVIRONMENT "VISCERA_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
