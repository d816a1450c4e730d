# SPDX-License-Identifier: Apache-2.0
# bench_implicit: CPU per 1 ms step, implicit_pcg against the explicit default (issue 17.3).
add_executable(bench_implicit ${CMAKE_CURRENT_LIST_DIR}/bench_implicit.c)
target_link_libraries(bench_implicit PRIVATE viscera_sim viscera_test_support)
# A quick run proves the benchmark still works (figures are not checked).
add_test(NAME bench_implicit_smoke COMMAND bench_implicit ${PROJECT_SOURCE_DIR}/assets --quick)
set_tests_properties(bench_implicit_smoke PROPERTIES LABELS bench TIMEOUT 120)
