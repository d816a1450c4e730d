# SPDX-License-Identifier: Apache-2.0
# Damaged recordings (issue 15 item 4): a real session is recorded on domain
# 193, then copies are damaged with sqlite3 edits and rec_flip (one bit of a
# stored sample) and every recording tool is run on them: no crash, no hang,
# a clear message, the documented exit status.
if(TARGET viscera-replay AND TARGET viscera-recinfo AND TARGET viscera-resim)
  add_executable(rec_flip rec_flip.c)
  target_link_libraries(rec_flip PRIVATE PkgConfig::SQLITE3)
  add_test(NAME damaged_recordings
    COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/damaged_recordings_test.sh ${PROJECT_BINARY_DIR} ${PROJECT_SOURCE_DIR}
      ${CMAKE_CURRENT_BINARY_DIR}/damaged_recordings.work $<TARGET_FILE:rec_flip>)
  set_tests_properties(damaged_recordings PROPERTIES LABELS integration TIMEOUT 240
    ENVIRONMENT "CYCLONEDDS_URI=file://${VISCERA_DDS_CONFIG};VISCERA_DOMAIN=193")
endif()
