# Molecular model (seed 000 eq. 6-11): force system, model wrapper, stiff and degenerate cases.
viscera_unit_test(NAME test_molecular SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_molecular.c LIBS viscera_sim)
