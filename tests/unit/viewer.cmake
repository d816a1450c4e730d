# Viewer: renderer, camera projection and PNG output (no DDS needed), and the
# keyframe + delta state of one organ.
if(TARGET viscera_render)
  viscera_unit_test(NAME test_render SOURCES test_render.c LIBS viscera_render)
  viscera_unit_test(NAME test_organ_state SOURCES test_organ_state.c ${PROJECT_SOURCE_DIR}/client/viewer/organ_state.c)
  target_include_directories(test_organ_state PRIVATE ${PROJECT_SOURCE_DIR}/client/viewer)
endif()
