# SPDX-License-Identifier: Apache-2.0
# bench_pbd: PBD / XPBD step time on the BarDemo bar and the spleen (figures are not checked).
add_executable(bench_pbd ${CMAKE_CURRENT_LIST_DIR}/bench_pbd.c)
target_link_libraries(bench_pbd PRIVATE viscera_sim)
add_test(NAME bench_pbd_smoke COMMAND bench_pbd ${PROJECT_SOURCE_DIR}/assets --quick)
set_tests_properties(bench_pbd_smoke PROPERTIES LABELS bench TIMEOUT 300)
