# Guiding hand, client side (issue 7): force law, role and peer slot, own-echo
# latency filter, log lines.
viscera_unit_test(NAME test_guide_force SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_guide_force.c LIBS viscera_haptic)
