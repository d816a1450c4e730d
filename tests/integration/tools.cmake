# SPDX-License-Identifier: Apache-2.0
# Tools over DDS (issue 4): grasp-pull-release, kidney-stone removal, two
# tools with tool-tool contact; real processes, domains 90-92.
if(TARGET viscera-recorder AND TARGET viscera-viewer)
  add_executable(rec_tools ${CMAKE_CURRENT_LIST_DIR}/rec_tools.c)
  target_link_libraries(rec_tools PRIVATE viscera_test_recording viscera_recording ${MATH_LIB})
  viscera_integration_test(grasp_pull 90 grasp_pull_test.sh)
  viscera_integration_test(stone_removal 91 stone_removal_test.sh)
  viscera_integration_test(two_tools 92 two_tools_test.sh)
endif()
