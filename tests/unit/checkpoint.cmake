# Server checkpoints (server/checkpoint.c): round trip, damaged and foreign
# files refused without touching the state, the background writer.
viscera_unit_test(NAME test_checkpoint SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_checkpoint.c LIBS viscera_server_core)
