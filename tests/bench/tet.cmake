# SPDX-License-Identifier: Apache-2.0
# bench_tet: tetrahedral mesh build time and quality per organ (figures are not checked).
add_executable(bench_tet ${CMAKE_CURRENT_LIST_DIR}/bench_tet.c)
target_link_libraries(bench_tet PRIVATE viscera_common)
add_test(NAME bench_tet_smoke COMMAND bench_tet ${PROJECT_SOURCE_DIR}/assets ${VISCERA_SHARED_DIR} --quick)
set_tests_properties(bench_tet_smoke PROPERTIES LABELS bench TIMEOUT 300)
