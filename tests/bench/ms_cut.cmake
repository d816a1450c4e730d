# SPDX-License-Identifier: Apache-2.0
# bench_ms_cut: three-stage mass-spring cutting: incision width over time
# (docs/methods.md D Fig. 6), cost per cut and per step; CSV and cairo plots.
add_executable(bench_ms_cut ${CMAKE_CURRENT_LIST_DIR}/bench_ms_cut.c)
target_link_libraries(bench_ms_cut PRIVATE viscera_test_support)
target_link_libraries(bench_ms_cut PRIVATE viscera_sim viscera_plot)
# Meshes come from VISCERA_SOURCE_DIR/assets/meshes, defaulting to this source tree.
target_compile_definitions(bench_ms_cut PRIVATE MSCUT_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
# A quick run proves the benchmark still works (figures are not checked).
add_test(NAME bench_ms_cut_smoke COMMAND bench_ms_cut --quick --out ${CMAKE_CURRENT_BINARY_DIR}/ms_cut_smoke)
set_tests_properties(bench_ms_cut_smoke PROPERTIES LABELS bench TIMEOUT 300
  ENVIRONMENT "VISCERA_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
