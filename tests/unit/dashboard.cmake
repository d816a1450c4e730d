# Dashboard: the wording and colours of a seat's state (no DDS, no drawing).
if(TARGET viscera-dashboard)
  viscera_unit_test(NAME test_seat_text SOURCES test_seat_text.c ${PROJECT_SOURCE_DIR}/client/dashboard/seat_text.c
                    LIBS viscera_dds)
  target_include_directories(test_seat_text PRIVATE ${PROJECT_SOURCE_DIR}/client/dashboard)
endif()
