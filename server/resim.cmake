# viscera-resim: deterministic re-simulation of a recording (issue 6).
# viscera_resim holds what needs no recording file (schedule, run and
# compare) so unit tests link it alone; the executable adds the reader
# (the recorder's recfile) and the CDR decoding.
add_library(viscera_resim STATIC resim_schedule.c resim_run.c)
target_include_directories(viscera_resim PUBLIC ${CMAKE_CURRENT_SOURCE_DIR})
target_link_libraries(viscera_resim PUBLIC viscera_server_core)

if(VISCERA_BUILD_RECORDER)
  add_executable(viscera-resim resim.c resim_recording.c resim_decode.c)
  target_link_libraries(viscera-resim PRIVATE viscera_resim viscera_recording ${MATH_LIB})
  # ddsi_cdrstream.h pulls in GNU `asm` (see client/recorder/CMakeLists.txt)
  set_target_properties(viscera-resim PROPERTIES C_EXTENSIONS ON)
endif()
