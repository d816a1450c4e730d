# SPDX-License-Identifier: Apache-2.0
# bash completion of every binary (issue 18): deploy/completion/viscera.bash.
set(_viscera_completion_bins "")
foreach(bin viscera-server viscera-resim viscera-haptic viscera-viewer viscera-dashboard viscera-control
            viscera-recorder viscera-recinfo viscera-replay viscera-report viscera-asset viscera-organ-gen)
  if(TARGET ${bin})
    list(APPEND _viscera_completion_bins $<TARGET_FILE:${bin}>)
  endif()
endforeach()
add_test(NAME bash_completion COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/completion_test.sh ${PROJECT_SOURCE_DIR}
                                      ${_viscera_completion_bins})
set_tests_properties(bash_completion PROPERTIES LABELS unit TIMEOUT 60)
