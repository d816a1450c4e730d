# Real-time loop threads (common/vrt.c): option parsing, one thread FIFO,
# threads it creates reset to SCHED_OTHER, the refusal path.
viscera_unit_test(NAME test_vrt SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_vrt.c LIBS Threads::Threads)
