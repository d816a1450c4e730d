# viscera-resim: deterministic re-simulation of a recording (issue 6).
# viscera_resim holds everything but main() so unit tests drive the schedule
# and the run directly; it reads recordings with the recorder's recfile, so
# it exists only when the recorder is built.
if(VISCERA_BUILD_RECORDER)
  add_library(viscera_resim STATIC resim_schedule.c resim_run.c resim_recording.c)
  target_include_directories(viscera_resim PUBLIC ${CMAKE_CURRENT_SOURCE_DIR})
  target_link_libraries(viscera_resim PUBLIC viscera_sim viscera_rec_decode ${MATH_LIB})
  add_executable(viscera-resim resim.c)
  target_link_libraries(viscera-resim PRIVATE viscera_resim)
endif()
