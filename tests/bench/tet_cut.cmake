# SPDX-License-Identifier: Apache-2.0
# bench_tet_cut: progressive cutting on the spleen-size XPBD model (docs/methods.md C
# Table 1 style) and 100 random incisions: time per cut, element growth,
# minimum quality; table, CSV and a cairo plot (figures are not checked).
pkg_check_modules(CAIRO_CUT REQUIRED IMPORTED_TARGET cairo)
add_executable(bench_tet_cut ${CMAKE_CURRENT_LIST_DIR}/bench_tet_cut.c)
target_include_directories(bench_tet_cut PRIVATE ${PROJECT_SOURCE_DIR}/tests/stability)
target_link_libraries(bench_tet_cut PRIVATE viscera_sim viscera_test_support PkgConfig::CAIRO_CUT)
add_test(NAME bench_tet_cut_smoke COMMAND bench_tet_cut ${PROJECT_SOURCE_DIR} --quick
  --csv ${CMAKE_CURRENT_BINARY_DIR}/tet_cut_smoke.csv --png ${CMAKE_CURRENT_BINARY_DIR}/tet_cut_smoke.png)
set_tests_properties(bench_tet_cut_smoke PROPERTIES LABELS bench TIMEOUT 300)
