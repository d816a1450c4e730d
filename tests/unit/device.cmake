# Devices and loss detection (issue 4): liveliness bookkeeping of server and
# haptic client.
viscera_unit_test(NAME test_liveliness SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_liveliness.c
                  LIBS viscera_haptic viscera_session)
# Mouse/keyboard driving: input -> pose mapping and input scripts (no display).
if(TARGET viscera_window)
  viscera_unit_test(NAME test_input_map SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_input_map.c LIBS viscera_window)
endif()
# Device registry: --device NAME, SDK devices absent from the build.
viscera_unit_test(NAME test_devices SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_devices.c LIBS viscera_haptic)
