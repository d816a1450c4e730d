# SPDX-License-Identifier: Apache-2.0
# Replay: a real session (deploy/session.sh: server, recorder, viewer, haptic
# on domain 61) is recorded, then viscera-replay republishes the recording
# into domain 62 where an unchanged viewer and a second recorder listen.
if(TARGET viscera-replay AND TARGET viscera-recorder AND TARGET viscera-recinfo)
  add_test(NAME replay
    COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/replay_test.sh ${PROJECT_BINARY_DIR} ${PROJECT_SOURCE_DIR}
      ${CMAKE_CURRENT_BINARY_DIR}/replay.work)
  set_tests_properties(replay PROPERTIES LABELS integration TIMEOUT 180
    ENVIRONMENT "CYCLONEDDS_URI=file://${VISCERA_DDS_CONFIG}")
endif()
