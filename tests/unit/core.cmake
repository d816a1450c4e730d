# Unit tests of the lead's areas: math, delta encoding, physics core (integrators,
# mass-spring models), proxy, tool input, haptic client pieces.
viscera_unit_test(NAME test_vmath SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_vmath.c)
viscera_unit_test(NAME test_mesh_delta SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_mesh_delta.c)
viscera_unit_test(NAME test_integrator SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_integrator.c LIBS viscera_sim)
viscera_unit_test(NAME test_mass_spring SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_mass_spring.c LIBS viscera_sim)
viscera_unit_test(NAME test_proxy SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_proxy.c LIBS viscera_sim)
viscera_unit_test(NAME test_tool_input SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_tool_input.c LIBS viscera_sim)
viscera_unit_test(NAME test_haptic_client SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_haptic_client.c LIBS viscera_haptic)
