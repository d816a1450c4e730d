# SPDX-License-Identifier: Apache-2.0
# Issue 17 item 5: a command's ContactFeedback is written before the
# step's tissue step, judged from the recording (rec_feedback_first.c).
# Domain 228 (the assigned 232 is above the CLI limit 0..230, common/cli.c).
if(TARGET viscera-recorder)
  add_executable(rec_feedback_first ${CMAKE_CURRENT_LIST_DIR}/rec_feedback_first.c)
  target_link_libraries(rec_feedback_first PRIVATE viscera_test_recording viscera_recording ${MATH_LIB})
  viscera_integration_test(feedback_first 228 feedback_first_test.sh)
endif()
