# SPDX-License-Identifier: Apache-2.0
# Palpation thresholds end to end (issue 4): the scripted palpation of the
# default scene must raise threshold-crossing SessionEvents and Metrics with
# time above the crossed thresholds, asserted in C over the recording
# (rec_palpation.c: SessionEvents, Metrics, the server's ToolMetrics).
# Domain 70.
if(TARGET viscera-recorder)
  add_executable(rec_palpation ${CMAKE_CURRENT_LIST_DIR}/rec_palpation.c)
  target_link_libraries(rec_palpation PRIVATE viscera_test_recording viscera_recording)
  viscera_integration_test(palpation_thresholds 70 palpation_test.sh)
endif()
