# SPDX-License-Identifier: Apache-2.0
# link_bench.sh: a remote session over an emulated link, delay x loss x
# reordering (issue 14; tests/network/sites.sh, needs root); link_plot draws
# its CSV. The smoke run: loopback and 50 ms at 5 % loss, with and without
# reordering (figures are not checked; skipped without root).
add_executable(link_plot ${CMAKE_CURRENT_LIST_DIR}/link_plot.c)
target_link_libraries(link_plot PRIVATE viscera_plot)
if(TARGET keyframe_wait)
  add_test(NAME bench_link_smoke COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/link_bench.sh --build ${PROJECT_BINARY_DIR}
           --out ${CMAKE_CURRENT_BINARY_DIR}/link_smoke --delays 50 --losses 5)
  set_tests_properties(bench_link_smoke PROPERTIES LABELS "bench;network" TIMEOUT 180 SKIP_RETURN_CODE 77
                       RESOURCE_LOCK viscera_sites ENVIRONMENT "VISCERA_DOMAIN=221")
endif()
