# SPDX-License-Identifier: Apache-2.0
# Recorder: a real publisher (product types, vdds) and viscera-recorder as
# separate processes on domain 41; the recording is then checked with
# viscera-recinfo and rec_check (sqlite3 + compiled-in descriptors). The
# same test kills a recorder with SIGKILL mid-session and checks the file
# still reads, and feeds recinfo a non-recording.
if(TARGET viscera-recorder AND TARGET viscera-recinfo)
  add_executable(rec_pub ${CMAKE_CURRENT_LIST_DIR}/rec_pub.c)
  target_link_libraries(rec_pub PRIVATE viscera_dds)

  add_executable(rec_check ${CMAKE_CURRENT_LIST_DIR}/rec_check.c)
  target_link_libraries(rec_check PRIVATE viscera_test_support)
  target_link_libraries(rec_check PRIVATE viscera_recording PkgConfig::SQLITE3)
  # ddsi_cdrstream.h pulls in GNU `asm` (see common/recording/CMakeLists.txt)
  set_target_properties(rec_check PROPERTIES C_EXTENSIONS ON)

  add_test(NAME recorder_generic
    COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/recorder_test.sh
      $<TARGET_FILE:viscera-recorder> $<TARGET_FILE:viscera-recinfo>
      $<TARGET_FILE:rec_pub> $<TARGET_FILE:rec_check>
      ${CMAKE_CURRENT_BINARY_DIR}/recorder_generic.work 41)
  set_tests_properties(recorder_generic PROPERTIES LABELS integration TIMEOUT 120
    ENVIRONMENT "CYCLONEDDS_URI=file://${VISCERA_DDS_CONFIG}")
endif()
