# SPDX-License-Identifier: Apache-2.0
# bench_models: CPU time per 1 ms step of every model on every organ, probe
# pressing, with the log-log slope against vertex count (issue 17; figures
# are not checked).
add_executable(bench_models ${CMAKE_CURRENT_LIST_DIR}/bench_models.c)
target_link_libraries(bench_models PRIVATE viscera_sim viscera_plot viscera_test_support)
add_test(NAME bench_models_smoke COMMAND bench_models --quick)
set_tests_properties(bench_models_smoke PROPERTIES LABELS bench TIMEOUT 300
  ENVIRONMENT "VISCERA_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
