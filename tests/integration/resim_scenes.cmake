# SPDX-License-Identifier: Apache-2.0
# Issue 16: every shipped scene, recorded with its trajectory, re-simulates
# bit for bit from the recording alone (resim_scenes_test.sh). Domain 197.
# The scripts play at twice their speed and five sessions record at a time:
# 65 s (CPU 21 s user) at load 15-19 on the 2-core machine, against 158 s
# (43 s) for the real-time scripts three at a time (both under nice 19,
# 2026-11-27). Its own timeout all the same.
if(TARGET viscera-resim)
  viscera_integration_test(resim_scenes 197 resim_scenes_test.sh)
  set_tests_properties(resim_scenes PROPERTIES TIMEOUT 420)
  if(VISCERA_SANITIZE)
    # Sanitized physics is 2-3 times slower: the scenes with buttons, a cut,
    # a grasp and two tools only, alone.
    set_tests_properties(resim_scenes PROPERTIES RUN_SERIAL TRUE
      ENVIRONMENT "${VISCERA_IT_ENV};VISCERA_DOMAIN=197;VISCERA_RESIM_SCENES=stone_removal cut_block_mass_spring grasp_pull two_tools")
  endif()
endif()

# Issue 16: SessionControls, a guided tool and two rebuilds re-simulate bit
# for bit; without the controls' AppliedInput they do not. Domain 198.
if(TARGET viscera-resim)
  add_executable(rec_applied ${CMAKE_CURRENT_LIST_DIR}/rec_applied.c)
  target_link_libraries(rec_applied PRIVATE viscera_test_recording viscera_recording)
  viscera_integration_test(resim_controls 198 resim_controls_test.sh)
endif()
