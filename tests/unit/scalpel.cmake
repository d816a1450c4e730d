# The scalpel in the runtime (issue 5, part 3): cutting structures only with
# a scalpel, blade_length validation, cuts of the xpbd spleen and the
# mass-spring tissue block, events, release mid-cut.
viscera_unit_test(NAME test_scalpel SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_scalpel.c LIBS viscera_sim)
