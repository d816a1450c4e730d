# SPDX-License-Identifier: Apache-2.0
# Recorder throughput under the issue 6 load (two haptic clients at 1 kHz,
# gallbladder at 60 Hz): a 4 s smoke run proves the benchmark works (figures
# are printed, not checked); deploy/bench.sh runs it for 45 s. Domain 111.
if(TARGET viscera-recorder AND TARGET viscera-recinfo AND TARGET viscera-resim)
  add_test(NAME recorder_load_smoke
    COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/recorder_load.sh ${PROJECT_BINARY_DIR} ${PROJECT_SOURCE_DIR}
      ${CMAKE_CURRENT_BINARY_DIR}/recorder_load.out 4)
  set_tests_properties(recorder_load_smoke PROPERTIES LABELS bench TIMEOUT 120
    ENVIRONMENT "CYCLONEDDS_URI=file://${VISCERA_DDS_CONFIG};VISCERA_DOMAIN=111")
endif()
