# viscera-resim pieces without DDS: schedule reconstruction on synthetic
# command / feedback arrays, and re-simulation of a synthetic recording.
if(TARGET viscera_resim)
  viscera_unit_test(NAME test_resim_schedule SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_resim_schedule.c LIBS viscera_resim)
  viscera_unit_test(NAME test_resim_run SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_resim_run.c LIBS viscera_resim viscera_session)
endif()
