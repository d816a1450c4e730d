# Recording files: the store writes what recfile reads, and viscera-recinfo
# turns missing, garbage, non-recording, truncated and corrupted files into
# a clear error naming the file and exit status 1, never a crash.
if(TARGET viscera_recording AND TARGET viscera-recinfo)
  viscera_unit_test(NAME test_recinfo_files SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_recinfo_files.c
    LIBS viscera_recording)
  target_compile_definitions(test_recinfo_files PRIVATE RECINFO_EXE="$<TARGET_FILE:viscera-recinfo>")
  add_dependencies(test_recinfo_files viscera-recinfo)
endif()

# The store on a full disk (a file-size limit stands in for it): stops
# cleanly, keeps exactly the committed batches, leaves a readable file.
if(TARGET viscera_recording)
  viscera_unit_test(NAME test_store_full SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_store_full.c LIBS viscera_recording)
endif()

# Decoding stored samples into the compiled-in types (common/recording/rec_decode.c).
if(TARGET viscera_recording)
  viscera_unit_test(NAME test_rec_decode SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_rec_decode.c LIBS viscera_recording)
  # ddsi_cdrstream.h pulls in GNU `asm` (see common/recording/CMakeLists.txt)
  set_target_properties(test_rec_decode PROPERTIES C_EXTENSIONS ON)
endif()

# Issue 6 metadata: participant announcement and sanitizing (vdds_ident),
# the replay pause schedule shift, the optional participants table.
if(TARGET viscera_recording AND TARGET viscera_replay)
  viscera_unit_test(NAME test_recmeta SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_recmeta.c
    LIBS viscera_replay viscera_recording)
endif()
