# Run-based mass-spring force and Jacobian loops against a one-spring-at-a-time
# reference on the kidney: sorted, shuffled, k_scale, f_res, zero-length spring.
viscera_unit_test(NAME test_ms_forces SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_ms_forces.c LIBS viscera_sim)
