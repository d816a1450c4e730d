# Instructor commands (server/session/session_control.c): pause/resume, threshold
# changes validated like scene files, resent copies dropped.
viscera_unit_test(NAME test_session_control SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_session_control.c LIBS viscera_session)
