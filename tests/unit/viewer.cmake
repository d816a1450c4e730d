# Viewer: renderer, camera projection and PNG output (no DDS needed).
if(TARGET viscera_render)
  viscera_unit_test(NAME test_render SOURCES test_render.c LIBS viscera_render)
endif()
viscera_unit_test(NAME test_organ_state SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_organ_state.c ${PROJECT_SOURCE_DIR}/client/viewer/organ_state.c)
