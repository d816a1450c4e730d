# Organ sleeping at rest (issue 7, load): evidence, reach, scene keys, and
# the same forces as a never-sleeping runtime on the kidney.
viscera_unit_test(NAME test_organ_sleep SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_organ_sleep.c LIBS viscera_sim)
# Quiet frames: an unchanged MeshDelta is not written again before the keepalive.
viscera_unit_test(NAME test_publisher_quiet SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_publisher_quiet.c LIBS viscera_session)
