# SPDX-License-Identifier: Apache-2.0
# Collision query benchmark: AABB tree, node grid and proxy costs; prints a table.
add_executable(bench_collision ${CMAKE_CURRENT_LIST_DIR}/bench_collision.c)
target_link_libraries(bench_collision PRIVATE viscera_sim viscera_test_support)
# A quick run proves the benchmark still works (figures are not checked).
add_test(NAME bench_collision_smoke COMMAND bench_collision ${PROJECT_SOURCE_DIR}/assets --quick)
set_tests_properties(bench_collision_smoke PROPERTIES LABELS bench TIMEOUT 300)
