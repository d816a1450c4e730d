# Issue 16: every shipped scene, recorded with its trajectory, re-simulates
# bit for bit from the recording alone (resim_scenes_test.sh). Domain 197.
# About 2 minutes on a loaded 2-core machine: its own timeout; three
# sessions record at a time, so it runs alone in the sanitizer pass.
if(TARGET viscera-resim)
  viscera_integration_test(resim_scenes 197 resim_scenes_test.sh)
  set_tests_properties(resim_scenes PROPERTIES TIMEOUT 420)
  if(VISCERA_SANITIZE)
    set_tests_properties(resim_scenes PROPERTIES RUN_SERIAL TRUE)
  endif()
endif()

# Issue 16: SessionControls, a guided tool and two rebuilds re-simulate bit
# for bit; without the controls' AppliedInput they do not. Domain 198.
if(TARGET viscera-resim)
  add_executable(rec_applied ${CMAKE_CURRENT_LIST_DIR}/rec_applied.c)
  target_link_libraries(rec_applied PRIVATE viscera_test_recording viscera_recording)
  viscera_integration_test(resim_controls 198 resim_controls_test.sh)
endif()
