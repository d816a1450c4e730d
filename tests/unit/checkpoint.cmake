# Server checkpoints (server/session/checkpoint.c): round trip, damaged and foreign
# files refused without touching the state, the background writer.
viscera_unit_test(NAME test_checkpoint SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_checkpoint.c LIBS viscera_session)
# Checkpoint format 2: stones, tasks, tallies and a cut xpbd organ restored
# bit for bit; crafted files (huge counts behind a valid CRC) refused.
viscera_unit_test(NAME test_checkpoint_state SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_checkpoint_state.c LIBS viscera_session)
