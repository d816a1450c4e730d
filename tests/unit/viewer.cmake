# Viewer: renderer, camera projection and PNG output (no DDS needed), and the
# keyframe + delta state of one organ.
if(TARGET viscera_view)
  viscera_unit_test(NAME test_render SOURCES test_render.c LIBS viscera_view)
  viscera_unit_test(NAME test_organ_state SOURCES test_organ_state.c LIBS viscera_view)
endif()
