# Three-stage mass-spring cutting (seed 004): Bezier, swept deletion, node
# matching, residual stress, mesh validity after cuts.
viscera_unit_test(NAME test_ms_cut SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_ms_cut.c LIBS viscera_sim)
